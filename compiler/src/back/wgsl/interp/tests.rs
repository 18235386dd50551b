//! Tests of the interpreted kernel's encoding: the words, run on the CPU as the kernel runs
//! them (in f32), agree with the reference run of programs, outlines and colour fields.

use super::*;
use crate::lower::Lowered;

/// The checked scene of `text`, lowered.
fn lowered(text: &str) -> Lowered {
    let (scene, diags, _) = crate::front::check_str("t.sdf", text);
    Lowered::new(&scene.unwrap_or_else(|| panic!("{diags:?}")))
}

/// The words of `programs` encoded with a register file of `file`.
fn encoded(programs: &Programs, file: usize) -> Vec<u32> {
    encode(programs, file, 128)
        .expect("fits")
        .chunks(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Runs the words as the kernel does, on the CPU, in f32.
fn run(words: &[u32], start: u32, p: [f32; 3], file: usize) -> [f32; 2] {
    let [a, b, _] = run3(words, start, [p, [0.0; 3]], file, &|_, _, _| unreachable!());
    [a, b]
}

/// The value of a call (`MESH`, `OUTLINE`): its opcode, operands and the data's word.
type Call<'a> = dyn Fn(u32, [f32; 3], u32) -> f32 + 'a;

/// [`run`] at the point and normal `[p, n]`, with the third value of `RETURN` (a colour's
/// blue), calls made by `call`.
fn run3(words: &[u32], start: u32, [p, n]: [[f32; 3]; 2], file: usize, call: &Call) -> [f32; 3] {
    let mut regs = vec![0f32; file + 1];
    let mut pc = start as usize;
    loop {
        let w = &words[pc * 4..pc * 4 + 4];
        let int = |x: u32| f32::from_bits(x) as u32;
        let h = int(w[0]);
        let arg = |k: usize| {
            if h & (0x100 << k) != 0 {
                regs[(int(w[k + 1]) as usize).min(file)]
            } else {
                f32::from_bits(w[k + 1])
            }
        };
        let (a, b, c) = (arg(0), arg(1), arg(2));
        let mut next = pc + 1;
        let op = h & 0xff;
        let v = match op {
            RETURN => return [a, b, c],
            1..=3 => p[(op - 1) as usize],
            NORMAL..=31 => n[(op - NORMAL) as usize],
            COPY => a,
            BLOCK => {
                if a >= b {
                    next = int(w[3]) as usize;
                }
                0.0
            }
            SELECT => crate::program::scalar::select(a, b, c),
            MESH => {
                next = pc + 2;
                call(MESH, [a, b, c], int(words[(pc + 1) * 4 + 1]))
            }
            OUTLINE => call(OUTLINE, [a, b, c], c as u32),
            o if o >= BINARY => {
                crate::program::scalar::binary(BINARIES[(o - BINARY) as usize], a, b)
            }
            o => crate::program::scalar::unary(UNARIES[(o - UNARY) as usize], a),
        };
        regs[((h >> DEST_SHIFT) as usize).min(file)] = v;
        pc = next;
    }
}

#[test]
fn encoded_programs_run_as_the_reference() {
    let text = "material a = phong { color: (1, 0, 0) };\nmaterial b = phong { color: (0, 1, 0) };\n\
        scene { smooth_union(0.3, sphere(1) @ a, box((0.5, 0.7, 0.4)).rotate_y(20deg).translate(1, 0, 0) @ b);\n\
        for i in 0..6 { torus(0.4, 0.1).translate(i - 3, 1.5, 0.5 * i) @ b; }\n\
        plane((0, 1, 0), -1) @ a; }";
    agrees(text, [4.0; 3]);
    // Many guarded blocks, nested (examples/lattice.sdf).
    agrees(
        include_str!("../../../../../examples/lattice.sdf"),
        [11.0, 0.8, 11.0],
    );
}

fn agrees(text: &str, extent: [f64; 3]) {
    let lowered = lowered(text);
    let program = &lowered.program;
    assert!(!program.blocks().is_empty(), "the scene has guarded blocks");
    let file = 64;
    let words = encoded(
        &Programs {
            main: program,
            media: None,
            colours: &[],
        },
        file,
    );
    let needed = registers(program);
    assert!(
        needed < program.len() / 2,
        "{needed} registers of {}",
        program.len()
    );
    let mut rng = crate::rng::Rng::new(7);
    for _ in 0..20_000 {
        let p = extent.map(|e| rng.range(-e, e) as f32);
        let regs = program.run::<f32>(p, |_| {});
        let want = [
            regs[program.distance().0 as usize],
            regs[program.material().0 as usize],
        ];
        let start = |k: usize| f32::from_bits(words[k]) as u32;
        let got = run(&words, start(0), p, file);
        assert_eq!(
            got.map(f32::to_bits),
            want.map(f32::to_bits),
            "map at {p:?}"
        );
        let d = run(&words, start(1), p, file);
        assert_eq!(d[0].to_bits(), want[0].to_bits(), "sdf at {p:?}");
    }
    let small = encode(
        &Programs {
            main: program,
            media: None,
            colours: &[],
        },
        needed - 1,
        128,
    );
    assert_eq!(small, Err(Unfit::Registers(needed, needed - 1)));
}

/// Text: each `OUTLINE` reads the words of its outline, appended after the programs, and
/// the programs run as the reference, bit for bit.
#[test]
fn encoded_outlines_run_as_the_reference() {
    let text = "scene { extrude(text(\"HELLO\", 0.7), 0.2, 0.01).translate(0, 0.3, -0.1);\n\
        box((1.45, 0.5, 0.1)).translate(0, 0.3, 0.05); extrude(text(\"ok\", 0.5), 0.1).translate(0, -1, 0); }";
    let lowered = lowered(text);
    let program = &lowered.program;
    assert_eq!(program.outlines().len(), 2);
    let file = 64;
    let programs = Programs {
        main: program,
        media: None,
        colours: &[],
    };
    assert_eq!(
        programs.calls(),
        Calls {
            meshes: false,
            outlines: true
        }
    );
    let words = encoded(&programs, file);
    // The outline whose words start at the call's word.
    let call = |op: u32, [x, y, _]: [f32; 3], at: u32| {
        assert_eq!(op, OUTLINE);
        let at = at as usize * 4;
        let o = program
            .outlines()
            .iter()
            .find(|o| {
                let w: Vec<u32> = o.words().iter().flatten().map(|v| v.to_bits()).collect();
                words.get(at..at + w.len()) == Some(&w[..])
            })
            .expect("an outline at the call's word");
        crate::program::outline::distance::<f32>(o, x, y)
    };
    let mut rng = crate::rng::Rng::new(5);
    for _ in 0..5_000 {
        let p = [2.0, 1.5, 0.5].map(|e: f64| rng.range(-e, e) as f32);
        let regs = program.run::<f32>(p, |_| {});
        let want = [
            regs[program.distance().0 as usize],
            regs[program.material().0 as usize],
        ];
        let start = |k: usize| f32::from_bits(words[k]) as u32;
        let [d, m, _] = run3(&words, start(0), [p, [0.0; 3]], file, &call);
        assert_eq!(
            [d, m].map(f32::to_bits),
            want.map(f32::to_bits),
            "map at {p:?}"
        );
        let [d, _, _] = run3(&words, start(1), [p, [0.0; 3]], file, &call);
        assert_eq!(d.to_bits(), want[0].to_bits(), "sdf at {p:?}");
    }
}

/// The colour fields' programs, encoded after the distance programs and found through
/// their table, run as their reference (`ColourProgram::eval`), bit for bit.
#[test]
fn encoded_colour_fields_run_as_the_reference() {
    let text = "material a = phong { color: field { vec3(0.5 + 0.5 * sin(4 * p.x), 0.3, fbm(p * 2, octaves: 2)) } };\n\
        material b = checker { a: field { vec3(0.2) * p.y }, b: field { vec3(voronoi(p * 3), 0.5, 0.5) } };\n\
        material c = phong { color: field { vec3(0.5) + 0.5 * n.zxy } };\n\
        scene { sphere(1) @ a; box(0.5).translate(2, 0, 0) @ b; (sphere(0.5) @ c).rotate_x(30deg).translate(0, 2, 0); }";
    let lowered = lowered(text);
    let colours = &lowered.colours;
    // c painted under a rotation and a translation: a copy of c carries them.
    assert_eq!(colours.programs.len(), 5);
    assert_eq!(
        colours.fields[1..],
        [
            [Some(0), None],
            [Some(1), Some(2)],
            [Some(3), None],
            [Some(4), None]
        ]
    );
    let file = 64;
    let words = encoded(
        &Programs {
            main: &lowered.program,
            media: None,
            colours: &colours.programs,
        },
        file,
    );
    let int = |k: usize| f32::from_bits(words[k]) as u32;
    let table = int(5) as usize;
    let mut rng = crate::rng::Rng::new(11);
    for _ in 0..2_000 {
        let p = [0; 3].map(|_| rng.range(-3.0, 3.0) as f32);
        let n = [0; 3].map(|_| rng.range(-1.0, 1.0) as f32);
        for (k, c) in colours.programs.iter().enumerate() {
            let start = int(4 * (table + k / 4) + k % 4);
            let got = run3(&words, start, [p, n], file, &|_, _, _| unreachable!());
            let want = c.eval::<f32>(p, n);
            assert_eq!(
                got.map(f32::to_bits),
                want.map(f32::to_bits),
                "{k} at {p:?}"
            );
        }
    }
}
