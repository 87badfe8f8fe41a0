//! Seeded input mutation for the fuzz tests (a dev-dependency of the
//! library's `tests/fuzz.rs` and of the CLI's parser tests): a SplitMix64
//! generator and byte, token, number and line edits of seed inputs. See
//! `crates/vibroimpact/tests/fuzz.rs` for the environment variables that
//! lengthen a run.

#![warn(missing_docs)]

use std::panic::{catch_unwind, AssertUnwindSafe};

/// SplitMix64: a small, well-mixed, seedable generator.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
    /// Uniform in [0, 1), 53 bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// 10^u with u uniform in [lo, hi].
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(lo + (hi - lo) * self.unit())
    }
    /// One of `items`, uniformly.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Cases per test: `VIBROIMPACT_FUZZ_CASES`, else `default`.
pub fn cases(default: usize) -> usize {
    std::env::var("VIBROIMPACT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The generator's seed: `VIBROIMPACT_FUZZ_SEED`, else a fixed one.
pub fn seed() -> u64 {
    std::env::var("VIBROIMPACT_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20_261_123)
}

/// Tokens worth inserting into TOML or CSV text.
pub const TOKENS: &[&str] = &[
    "=",
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    ",",
    "\"",
    "#",
    "\n",
    " ",
    ".",
    "-",
    "e",
    "0",
    "1",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "-0.0",
    "0.0",
    "1e20",
    "1e-300",
    "18446744073709551616",
    "9999999999",
    "true",
    "\"wall\"",
    "[[body]]",
    "[[contact]]",
    "[[spring]]",
    "[[force]]",
    "[row]",
    "[excitation]",
    "[simulation]",
    "count = 3",
    "law = \"hertz\"",
    "law = \"exponential\"",
    "type = \"accelerogram\"",
    "\u{0}",
    "\u{1}",
    "\t",
    "\r",
    "é",
    "\u{feff}",
];

/// Numbers that probe the validation of every key.
pub const NUMBERS: &[&str] = &[
    "0", "-1", "1e308", "1e-308", "5e-324", "nan", "inf", "-inf", "1e12", "1e-12", "1e9", "-1e-9",
    "2", "3.5", "100000", "1e300",
];

/// One random edit of `text`.
pub fn mutate(rng: &mut Rng, text: &str) -> String {
    let mut s = text.to_string();
    let len = s.len();
    let at = |rng: &mut Rng, s: &str| {
        let mut i = rng.below(s.len() + 1);
        while !s.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    match rng.below(6) {
        0 if len > 0 => {
            let a = at(rng, &s);
            let b = (a + 1 + rng.below(12)).min(s.len());
            let mut b = b;
            while !s.is_char_boundary(b) {
                b -= 1;
            }
            s.replace_range(a..b.max(a), "");
        }
        1 => {
            let a = at(rng, &s);
            let token = *rng.pick(TOKENS);
            s.insert_str(a, token);
        }
        2 => {
            // Replace one number with an extreme one.
            let starts: Vec<usize> = s
                .char_indices()
                .filter(|&(i, c)| {
                    c.is_ascii_digit() && (i == 0 || !s.as_bytes()[i - 1].is_ascii_alphanumeric())
                })
                .map(|(i, _)| i)
                .collect();
            if !starts.is_empty() {
                let a = *rng.pick(&starts);
                let b = s[a..]
                    .find(|c: char| !(c.is_ascii_digit() || "eE+-.".contains(c)))
                    .map_or(s.len(), |k| a + k);
                let number = *rng.pick(NUMBERS);
                s.replace_range(a..b, number);
            }
        }
        3 | 4 => {
            let mut lines: Vec<&str> = s.lines().collect();
            if !lines.is_empty() {
                let i = rng.below(lines.len());
                let j = rng.below(lines.len());
                if rng.below(2) == 0 {
                    lines.swap(i, j);
                } else {
                    lines.insert(j, lines[i]);
                }
                s = lines.join("\n");
            }
        }
        _ => {
            let a = at(rng, &s);
            s.insert(a, char::from(rng.below(128) as u8));
        }
    }
    s
}

/// One to six edits of a text drawn from `corpus`.
pub fn mutant(rng: &mut Rng, corpus: &[&str]) -> String {
    let mut s = rng.pick(corpus).to_string();
    for _ in 0..1 + rng.below(6) {
        s = mutate(rng, &s);
    }
    s
}

/// Runs `case` on every input, reporting the input that panicked.
pub fn no_panics(what: &str, inputs: impl Iterator<Item = String>, case: impl Fn(&str)) {
    for (k, input) in inputs.enumerate() {
        if catch_unwind(AssertUnwindSafe(|| case(&input))).is_err() {
            panic!("{what} case {k} panicked on input:\n{input:?}");
        }
    }
}
