//! The text of one PTX function under construction: virtual registers, labels, local
//! arrays and instruction lines, with register numbering that depends only on the order
//! of the calls (so the same module always gives the same text).

use smallvec::SmallVec;
use std::fmt::{self, Write};

/// A PTX register class; each has its own numbered family (`%p1`, `%r1`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Class {
    /// `.pred`: booleans.
    Pred,
    /// `.b16`: bytes of booleans on their way to and from memory.
    B16,
    /// `.b32`: `i32` and `u32`.
    B32,
    /// `.f32`.
    F32,
    /// `.b64`: addresses.
    B64,
    /// `.f64`: only inside the large-argument trigonometric reduction.
    F64,
}

const CLASSES: [(Class, &str, &str); 6] = [
    (Class::Pred, "pred", "%p"),
    (Class::B16, "b16", "%rs"),
    (Class::B32, "b32", "%r"),
    (Class::F32, "f32", "%f"),
    (Class::B64, "b64", "%rd"),
    (Class::F64, "f64", "%fd"),
];

impl Class {
    fn index(self) -> usize {
        self as usize
    }
}

/// A virtual register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Reg {
    pub class: Class,
    pub n: u32,
}

impl fmt::Display for Reg {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        // Written by hand, not with `write!`: a kernel has tens of thousands of operands, and
        // the formatting machinery was most of the translator's time.
        f.write_str(CLASSES[self.class.index()].2)?;
        f.write_str(decimal(&mut [0; 10], self.n))
    }
}

/// `n` in decimal, written into the end of `buf`.
fn decimal(buf: &mut [u8; 10], mut n: u32) -> &str {
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    std::str::from_utf8(&buf[i..]).unwrap_or("0")
}

/// `0fXXXXXXXX`: the bits of an `f32` in PTX's exact hexadecimal notation.
fn f32_bits(buf: &mut [u8; 10], bits: u32) -> &str {
    const HEX: &[u8; 16] = b"0123456789ABCDEF";
    buf[0] = b'0';
    buf[1] = b'f';
    for k in 0..8 {
        buf[2 + k] = HEX[((bits >> (28 - 4 * k)) & 0xF) as usize];
    }
    std::str::from_utf8(&buf[..]).unwrap_or("0f00000000")
}

/// A scalar operand: a register or an immediate (immediates need no instruction, so
/// constants cost nothing until an instruction reads them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Op {
    Reg(Reg),
    /// An `f32`, by its bits (written `0fXXXXXXXX`, exact).
    F32(u32),
    I32(i32),
    U32(u32),
    Bool(bool),
}

impl Op {
    pub fn f32(x: f32) -> Op {
        Op::F32(x.to_bits())
    }
}

impl fmt::Display for Op {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match *self {
            Op::Reg(r) => r.fmt(f),
            Op::F32(bits) => f.write_str(f32_bits(&mut [0; 10], bits)),
            Op::I32(i) => write!(f, "{i}"),
            Op::U32(u) => write!(f, "{u}"),
            Op::Bool(b) => write!(f, "{}", u8::from(b)),
        }
    }
}

impl From<Reg> for Op {
    fn from(r: Reg) -> Op {
        Op::Reg(r)
    }
}

/// A branch target, e.g. `$L3_loop_end`.
pub(super) type Label = String;

/// One PTX function's body text and the declarations it needs.
#[derive(Debug, Default)]
pub(super) struct Out {
    text: String,
    counts: [u32; 6],
    labels: u32,
    locals: String,
    local_count: u32,
}

impl Out {
    /// A fresh register of class `c`.
    pub fn reg(&mut self, c: Class) -> Reg {
        let n = &mut self.counts[c.index()];
        *n += 1;
        Reg { class: c, n: *n }
    }

    /// A fresh label whose name says what it marks.
    pub fn label(&mut self, what: &str) -> Label {
        self.labels += 1;
        format!("$L{}_{what}", self.labels)
    }

    /// A fresh label number, for a group of labels that belong together.
    pub fn label_group(&mut self) -> u32 {
        self.labels += 1;
        self.labels
    }

    /// One instruction line.
    pub fn ins(&mut self, args: fmt::Arguments) {
        self.text.push('\t');
        let _ = self.text.write_fmt(args);
        self.text.push('\n');
    }

    /// A comment line (PTX is ASCII: other characters become `?`).
    pub fn comment(&mut self, args: fmt::Arguments) {
        self.text.push_str("\t// ");
        let start = self.text.len();
        let _ = self.text.write_fmt(args);
        if !self.text[start..].is_ascii() {
            let tail: String = self.text[start..]
                .chars()
                .map(|c| if c.is_ascii() { c } else { '?' })
                .collect();
            self.text.truncate(start);
            self.text.push_str(&tail);
        }
        self.text.push('\n');
    }

    /// Places `label` here.
    pub fn place(&mut self, label: &str) {
        self.text.push_str(label);
        self.text.push_str(":\n");
    }

    /// Raw text (an opening or closing brace of a call block).
    pub fn raw(&mut self, s: &str) {
        self.text.push_str(s);
    }

    /// Declares a `.local` byte array of `size` bytes (rounded up to 16) aligned to 16;
    /// returns its name.
    pub fn local_array(&mut self, size: u32, what: &str) -> String {
        self.local_count += 1;
        let name = format!("__local{}_{what}", self.local_count);
        let _ = writeln!(
            self.locals,
            "\t.local .align 16 .b8 {name}[{}];",
            size.max(1).next_multiple_of(16)
        );
        name
    }

    /// The declarations (registers, local arrays) followed by the body.
    pub fn finish(self) -> String {
        let mut s = String::with_capacity(self.text.len() + 256);
        for (c, ty, prefix) in CLASSES {
            let n = self.counts[c.index()];
            if n > 0 {
                let _ = writeln!(s, "\t.reg .{ty} {prefix}<{}>;", n + 1);
            }
        }
        s.push_str(&self.locals);
        s.push_str(&self.text);
        s
    }
}

/// `s` with every character outside ASCII (which PTX forbids) replaced by `?`.
pub(super) fn ascii(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii() { c } else { '?' })
        .collect()
}

/// Writes one instruction: `ins!(out, "add.f32 {}, {}, {};", d, a, b)`.
macro_rules! ins {
    ($out:expr, $($arg:tt)*) => { $out.ins(format_args!($($arg)*)) };
}
pub(super) use ins;

/// The leaves of a value (one operand per scalar), stored inline up to a `vec4`: most
/// expressions are scalars or small vectors, and a kernel has tens of thousands of them.
pub(super) type Leaves = SmallVec<[Op; 4]>;

#[cfg(test)]
mod tests {
    use super::*;

    /// The hand-written formatting writes what `format!` would.
    #[test]
    fn registers_and_immediates_are_written_as_format_would() {
        for n in [0, 1, 9, 10, 99, 100, 65_535, 1_000_000, u32::MAX] {
            assert_eq!(decimal(&mut [0; 10], n), n.to_string());
            let r = Reg {
                class: Class::F32,
                n,
            };
            assert_eq!(r.to_string(), format!("%f{n}"));
        }
        for bits in [0, 1, 0x0123_4567, 0x89AB_CDEF, 0x3F80_0000, u32::MAX] {
            assert_eq!(f32_bits(&mut [0; 10], bits), format!("0f{bits:08X}"));
            assert_eq!(Op::F32(bits).to_string(), format!("0f{bits:08X}"));
        }
    }
}
