// The web panel served to the network, in headless Debian chromium (playwright-core): the page
// asks for a login and shows nothing of the machine before it; a wrong password is refused
// with the reason; the right one opens the panel with the operator's name, and a button press
// goes out (as a command event naming the operator, checked by tests/web_login.rs).
// Usage: node login.cjs <url> <operator> <password>. Exits 1 with the reason on a failure.
"use strict";
const { fail, launch } = require("./browser.cjs");
const [url, operator, password] = process.argv.slice(2);

(async () => {
  const browser = await launch();
  const page = await browser.newPage();
  page.on("pageerror", (e) => fail(`page error: ${e.message}`));
  await page.goto(url);
  await page.waitForSelector("#login:not([hidden])", { timeout: 20000 });
  if (!(await page.isHidden("main"))) fail("the panel shows the machine before a login");
  console.log("ok   login asked, panel hidden");
  await page.fill("#login_name", operator);
  await page.fill("#login_password", "not the password");
  await page.click("#login_go");
  await page.waitForFunction(() => document.getElementById("login_message").textContent.includes("refused"),
    null, { timeout: 20000 });
  console.log(`ok   wrong password: ${await page.textContent("#login_message")}`);
  await page.fill("#login_password", password);
  await page.click("#login_go");
  await page.waitForFunction(() => document.getElementById("link").textContent === "online", null, { timeout: 20000 });
  const shown = await page.textContent("#operator_name");
  if (shown !== operator) fail(`operator shown as ${shown}`);
  console.log(`ok   logged in as ${shown}, panel online`);
  await page.click("#feed_hold");
  await page.waitForFunction(() => document.getElementById("message").textContent.length > 0, null, { timeout: 10000 });
  console.log(`ok   feed hold answered: ${await page.textContent("#message")}`);
  await browser.close();
})().catch((e) => fail(e.message));
