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
