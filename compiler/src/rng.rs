//! A small deterministic generator of pseudo-random numbers (xorshift64*), the one the tests
//! draw their points, rays, mutations and formulas from, so that every failure reproduces. The
//! language's `hash` builtin is a hash of its argument, not a generator (check/builtins.rs).

/// A xorshift64* generator.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator started from `seed` (any value, zero included).
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A whole number below `n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// A point uniform in the cube [-s, s]³.
    pub fn point(&mut self, s: f64) -> [f64; 3] {
        [self.range(-s, s), self.range(-s, s), self.range(-s, s)]
    }

    /// A random formula `depth` operations deep (for the tests of the bound analysis): a leaf
    /// is one of `leaves` or a number in [-2, 2); an operation one of `forms`, its operands
    /// `{a}` and `{b}` formulas one level less deep.
    #[cfg(test)]
    pub(crate) fn formula(&mut self, depth: u32, leaves: &[&str], forms: &[&str]) -> String {
        if depth == 0 {
            return match leaves.get(self.below(leaves.len() + 1)) {
                Some(leaf) => leaf.to_string(),
                None => format!("{:.2}", self.range(-2.0, 2.0)),
            };
        }
        let a = self.formula(depth - 1, leaves, forms);
        let b = self.formula(depth - 1, leaves, forms);
        forms[self.below(forms.len())]
            .replace("{a}", &a)
            .replace("{b}", &b)
    }
}
