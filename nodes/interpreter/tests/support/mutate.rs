//! A seeded program mutator shared by the fuzz and golden-mutant tests: bytes from a
//! G-code alphabet inserted, overwritten or removed, tokens inserted, whole lines duplicated,
//! dropped or moved. Deterministic for a seed, so a mutant can be made again.

const ALPHABET: &[u8] = b"GXYZIJKRFPQLDHMSTNO#[]=.-+0123456789 \n()%/EQNTWHILDO";

/// A small deterministic generator (xorshift64*).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

pub fn mutate(seed: &str, tokens: &[&str], rng: &mut Rng) -> String {
    let mut text: Vec<u8> = seed.as_bytes().to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(text.len() + 1);
        match rng.below(6) {
            0 if at < text.len() => {
                text.remove(at);
            }
            1 => text.insert(at, ALPHABET[rng.below(ALPHABET.len())]),
            2 if at < text.len() => text[at] = ALPHABET[rng.below(ALPHABET.len())],
            3 => {
                let token = tokens[rng.below(tokens.len())].as_bytes();
                text.splice(at..at, token.iter().copied());
            }
            _ => {
                // Duplicate, drop or move a whole line.
                let lines: Vec<&[u8]> = text.split(|&c| c == b'\n').collect();
                let mut lines: Vec<Vec<u8>> = lines.into_iter().map(<[u8]>::to_vec).collect();
                let i = rng.below(lines.len());
                let j = rng.below(lines.len());
                match rng.below(3) {
                    0 => {
                        let l = lines[i].clone();
                        lines.insert(j, l);
                    }
                    1 => {
                        lines.remove(i);
                    }
                    _ => lines.swap(i, j),
                }
                text = lines.join(&b'\n');
            }
        }
    }
    String::from_utf8_lossy(&text).into_owned()
}

/// A seeded search over mutants of `seeds`, run on a worker thread and watched for a hang.
#[allow(dead_code)]
pub struct Search {
    /// (name, text) of each seed program.
    pub seeds: Vec<(String, String)>,
    pub tokens: &'static [&'static str],
    /// Mutants per seed and the generator's seed, unless `<env>_MUTANTS` / `<env>_SEED` say
    /// otherwise (a longer search by hand).
    pub mutants: usize,
    pub seed: u64,
    pub env: &'static str,
    /// Applied to every mutant after `mutate` (arbitrary bytes, say); `None`: none.
    pub extra: Option<fn(String, &mut Rng) -> String>,
    /// How one mutant ended: `Ok(true)` in an alarm, `Ok(false)` at its end, `Err` with what
    /// went wrong.
    pub examine: fn(&str) -> Result<bool, String>,
    /// The whole search must answer within it, or it counts as hanging.
    pub deadline: std::time::Duration,
    pub stack_bytes: usize,
}

#[allow(dead_code)]
impl Search {
    /// Runs the search; panics with the failing mutant (or the one running at the deadline).
    /// Returns (mutants run, of them ended in an alarm).
    pub fn run(self) -> (usize, usize) {
        use std::sync::mpsc;
        let (tx, rx) = mpsc::channel::<Result<(usize, usize), String>>();
        let deadline = self.deadline;
        std::thread::Builder::new()
            .stack_size(self.stack_bytes)
            .spawn(move || {
                let env = |what: &str| {
                    std::env::var(format!("{}_{what}", self.env))
                        .ok()
                        .and_then(|v| v.parse::<u64>().ok())
                };
                let mut rng = Rng(env("SEED").unwrap_or(self.seed) | 1);
                let mutants = env("MUTANTS").map_or(self.mutants, |n| n as usize);
                let (mut alarms, mut runs) = (0, 0);
                for (name, seed) in &self.seeds {
                    for _ in 0..mutants {
                        let mut text = mutate(seed, self.tokens, &mut rng);
                        if let Some(extra) = self.extra {
                            text = extra(text, &mut rng);
                        }
                        // Tell the watcher which program runs, so a hang names it.
                        let _ = tx.send(Err(format!("running a mutant of {name}:\n{text}")));
                        match (self.examine)(&text) {
                            Ok(alarm) => alarms += usize::from(alarm),
                            Err(problem) => {
                                let _ = tx.send(Err(format!(
                                    "FAIL {problem} for a mutant of {name}:\n{text}"
                                )));
                                return;
                            }
                        }
                        runs += 1;
                    }
                }
                let _ = tx.send(Ok((runs, alarms)));
            })
            .expect("fuzz thread");
        let start = std::time::Instant::now();
        let mut last = String::new();
        loop {
            let left = deadline.saturating_sub(start.elapsed());
            match rx.recv_timeout(left) {
                Ok(Ok(counts)) => return counts,
                Ok(Err(msg)) if msg.starts_with("FAIL") => panic!("{msg}"),
                Ok(Err(msg)) => last = msg,
                Err(_) => panic!("no answer within {deadline:?}; last: {last}"),
            }
        }
    }
}
