// What the browser tests share: headless Debian chromium through playwright-core (no downloaded
// browser; PLAYWRIGHT_CORE names the module, CHROMIUM the binary), and how a test fails.
"use strict";
const { chromium } = require(process.env.PLAYWRIGHT_CORE || "playwright-core");

function fail(why) {
  console.error(`FAIL: ${why}`);
  process.exit(1);
}

function launch() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
}

module.exports = { fail, launch };
