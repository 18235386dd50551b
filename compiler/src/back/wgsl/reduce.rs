//! The reduction of a frame's per-pixel statistics on the device: a small WGSL module, the same
//! for every scene, whose one entry point sums the renderer kernel's statistics words
//! ([`super::STATS_WORDS`] a pixel) without atomics, so that its PTX translation
//! ([`ptx`]) runs on CUDA as it runs through wgpu. The host reads back a few kilobytes (the
//! sums `sdfc render --stats` prints) instead of 32 bytes a pixel.
//!
//! Each dispatch is one [`Query`] (a record of [`QUERY_WORDS`] words in a read-only storage
//! buffer, bound at a dynamic offset): thread `t` of `threads` takes the items `t`,
//! `t + threads`, … of its input and writes one record of [`RECORD`] words.
//! - Stage 0 reads the statistics of the pixels `first .. first + count` and writes (or, with
//!   `add`, adds to) its partial record in `partial`; one stage-0 dispatch per range of pixels
//!   (several bands of a frame add to the same records).
//! - Stage 1 sums the `count` partial records into `total`, which the host reads back and adds
//!   up.
//!
//! The mode says what a record holds: 0 the sum of each statistics word as a 64-bit count
//! (low word, high word: 18 words) and, in word 18, the most steps of a pixel; 1 a histogram
//! of the pixels' steps in [`BINS`] bins of `width` steps from `base` (a pixel outside them
//! counts in none). The host finds the 99th percentile of the steps with histograms of
//! narrower bins around it, a round each, until the bins are one step wide
//! (runtime/src/gpu/reduce.rs).

use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};

/// The entry point.
pub const ENTRY_POINT: &str = "reduce";
/// Threads of a workgroup (one dimension).
pub const WORKGROUP: u32 = 64;
/// Bins of a histogram, and words of a record.
pub const BINS: u32 = 64;
/// Words of a record (partial or total).
pub const RECORD: u32 = BINS;
/// Words of a query (binding 0): first, count, threads, stage, mode, base, width, add.
pub const QUERY_WORDS: u32 = 8;
/// Where the sums mode puts the most steps of a pixel in a record.
pub const MOST_STEPS_WORD: u32 = 18;

/// The module's text. Bindings (group 0): 0 the query (read-only storage at a dynamic offset,
/// not a uniform: a software adapter compiles a variant of a shader for each value of a uniform
/// that decides a branch), 1 the kernel's statistics, 2 the partial records, 3 the totals.
pub const SOURCE: &str = r#"
struct Query {
    first: u32,
    count: u32,
    threads: u32,
    stage: u32,
    mode: u32,
    base: u32,
    width: u32,
    add: u32,
}

@group(0) @binding(0) var<storage, read> query: Query;
@group(0) @binding(1) var<storage, read> stats: array<u32>;
@group(0) @binding(2) var<storage, read_write> partial: array<u32>;
@group(0) @binding(3) var<storage, read_write> total: array<u32>;

const RECORD: u32 = 64u;
const BINS: u32 = 64u;
const STATS_WORDS: u32 = 9u;

@compute @workgroup_size(64, 1, 1)
fn reduce(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = gid.x;
    if t >= query.threads {
        return;
    }
    let out = t * RECORD;
    var acc: array<u32, 64>;
    if query.stage == 0u && query.add == 1u {
        for (var k = 0u; k < RECORD; k++) {
            acc[k] = partial[out + k];
        }
    }
    for (var i = t; i < query.count; i += query.threads) {
        if query.stage == 0u {
            let s = (query.first + i) * STATS_WORDS;
            if query.mode == 0u {
                for (var k = 0u; k < STATS_WORDS; k++) {
                    let v = stats[s + k];
                    let lo = acc[2u * k] + v;
                    acc[2u * k + 1u] += select(0u, 1u, lo < v);
                    acc[2u * k] = lo;
                }
                acc[18] = max(acc[18], stats[s]);
            } else {
                let v = stats[s];
                if v >= query.base {
                    let b = (v - query.base) / query.width;
                    if b < BINS {
                        acc[b] += 1u;
                    }
                }
            }
        } else {
            let r = i * RECORD;
            if query.mode == 0u {
                for (var k = 0u; k < STATS_WORDS; k++) {
                    let v = partial[r + 2u * k];
                    let lo = acc[2u * k] + v;
                    acc[2u * k + 1u] += partial[r + 2u * k + 1u] + select(0u, 1u, lo < v);
                    acc[2u * k] = lo;
                }
                acc[18] = max(acc[18], partial[r + 18u]);
            } else {
                for (var k = 0u; k < BINS; k++) {
                    acc[k] += partial[r + k];
                }
            }
        }
    }
    if query.stage == 0u {
        for (var k = 0u; k < RECORD; k++) {
            partial[out + k] = acc[k];
        }
    } else {
        for (var k = 0u; k < RECORD; k++) {
            total[out + k] = acc[k];
        }
    }
}
"#;

/// What a dispatch computes ([`SOURCE`]'s `Query`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Query {
    /// Stage 0: the first pixel; stage 1: unused.
    pub first: u32,
    /// Stage 0: pixels; stage 1: partial records.
    pub count: u32,
    /// Threads of the dispatch (each writes one record).
    pub threads: u32,
    /// 0: pixels into partial records; 1: partial records into totals.
    pub stage: u32,
    /// 0: sums and the most steps; 1: a histogram of steps.
    pub mode: u32,
    /// The histogram's first step count.
    pub base: u32,
    /// The width of its bins in steps (at least 1).
    pub width: u32,
    /// Stage 0: add to the partial records instead of writing them.
    pub add: bool,
}

impl Query {
    /// The query's words, as the module reads them.
    pub fn words(&self) -> [u32; QUERY_WORDS as usize] {
        [
            self.first,
            self.count,
            self.threads,
            self.stage,
            self.mode,
            self.base,
            self.width.max(1),
            self.add as u32,
        ]
    }
}

/// [`SOURCE`] parsed and validated by naga.
pub(crate) fn module() -> (naga::Module, ModuleInfo) {
    let module = naga::front::wgsl::parse_str(SOURCE).expect("the reduction's WGSL parses");
    let info = Validator::new(ValidationFlags::all(), Capabilities::empty())
        .validate(&module)
        .expect("the reduction's WGSL is valid");
    (module, info)
}

/// The reduction as PTX for `sm` (its parameters the four bindings in order).
pub fn ptx(sm: u32) -> Result<crate::back::ptx::Ptx, crate::back::ptx::Error> {
    let (module, info) = module();
    let options = crate::back::ptx::Options {
        sm,
        entry_point: ENTRY_POINT.into(),
    };
    crate::back::ptx::write(&module, &info, &options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reduction_validates_and_translates_to_ptx() {
        let (module, _) = module();
        let entry = &module.entry_points[0];
        assert_eq!(entry.name, ENTRY_POINT);
        assert_eq!(entry.workgroup_size, [WORKGROUP, 1, 1]);
        let ptx = ptx(90).expect("PTX");
        assert!(ptx.text.contains(".entry reduce"), "{}", ptx.text);
        // The four bindings, in order, each a global address.
        let bindings: Vec<u32> = ptx.params.iter().map(|p| p.binding).collect();
        assert_eq!(bindings, [0, 1, 2, 3]);
        assert_eq!(RECORD, BINS);
        assert!(SOURCE.contains(&format!("const RECORD: u32 = {RECORD}u;")));
        assert!(SOURCE.contains(&format!("const BINS: u32 = {BINS}u;")));
        assert!(SOURCE.contains(&format!("acc[{MOST_STEPS_WORD}]")));
        assert!(SOURCE.contains(&format!("@workgroup_size({WORKGROUP}, 1, 1)")));
        assert!(SOURCE.contains(&format!(
            "const STATS_WORDS: u32 = {}u;",
            super::super::STATS_WORDS
        )));
    }
}
