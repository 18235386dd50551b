//! Tests of the tape's compiler: the values a block gathers are those a scan of its
//! instructions finds.

use super::Compiler;
use crate::eval::Outputs;
use crate::front::check_str;
use crate::lower::lower;
use crate::program::{Op, Program, Reg};

/// The registers block `b` of `c`'s program reads from before it, found the slow way:
/// every live instruction inside it, every live block inside it, its results.
fn outside_reads_by_scanning(c: &Compiler, b: usize) -> Vec<Reg> {
    let block = c.program.blocks()[b];
    let mut reads = Vec::new();
    for i in block.start..block.end {
        if c.live[i] {
            reads.extend(c.fusions.reads(c.program, i));
        }
    }
    for (nb, inner) in c.program.blocks().iter().enumerate() {
        let within = inner.start >= block.start && inner.end <= block.end && nb != b;
        if within && c.live_blocks[nb] {
            reads.extend([inner.bound, inner.best]);
        }
    }
    for i in block.end..block.end + block.results {
        if let (true, Op::Phi(then, _)) = (c.live[i], c.ops()[i]) {
            reads.push(then);
        }
    }
    reads.retain(|&r| (r.0 as usize) < block.start && !c.is_const(r));
    reads.sort();
    reads.dedup();
    reads
}

/// A scene of `n` objects in a loop, some under smooth blends and transforms, so that
/// its program holds blocks nested several deep.
fn many(n: usize) -> Program {
    let text = format!(
        "material a = phong {{ color: (1, 0, 0) }};
         material b = phong {{ color: (0, 0, 1) }};
         scene {{
           plane((0, 1, 0), -2) @ a;
           for i in 0..{n} {{
             let s = smooth_union(0.1, sphere(0.2), box((0.1, 0.3, 0.1)).rotate_y(30deg * i));
             if hash(i) < 0.5 {{ s.translate(hash(3 * i) * 20, hash(3 * i + 1), hash(3 * i + 2) * 20) @ a }}
             else {{ torus(0.3, 0.1).translate(hash(3 * i) * 20, 1, hash(3 * i + 2) * 20) @ b }};
           }}
         }}"
    );
    let (scene, diagnostics, _) = check_str("many.sdf", &text);
    assert!(diagnostics.iter().all(|d| !d.is_error()), "{diagnostics:?}");
    lower(&scene.expect("a scene"))
}

#[test]
fn gathered_reads_equal_the_scan_of_every_block() {
    for n in [1, 7, 64, 300] {
        let program = many(n);
        assert!(program.blocks().len() >= n / 4, "{n}: few blocks");
        for outputs in [Outputs::Distance, Outputs::DistanceAndMaterial] {
            let mut roots = vec![program.distance()];
            if outputs == Outputs::DistanceAndMaterial {
                roots.push(program.material());
            }
            let c = Compiler::new(&program, &roots);
            let depth = program.blocks().iter().enumerate().any(|(b, block)| {
                program.blocks()[b + 1..]
                    .iter()
                    .any(|inner| inner.start >= block.start && inner.end <= block.end)
            });
            assert!(n < 64 || depth, "{n}: no nested blocks");
            // What the walk gathers stays within a few registers a block: the sets that
            // blocks hand outwards do not grow with the number of blocks around them.
            let gathered: usize = c.outside.iter().map(Vec::len).sum();
            let blocks = program.blocks().len();
            assert!(
                gathered <= 8 * blocks,
                "{n}: {gathered} for {blocks} blocks"
            );
            for b in 0..program.blocks().len() {
                assert_eq!(
                    c.outside_reads(b),
                    outside_reads_by_scanning(&c, b),
                    "{n} objects, block {b}"
                );
            }
        }
    }
}
