//! Tests of the instances as data: every instance written once, groups skipping forward, and
//! a model of the kernel's walk (nearest first, with its cache of the last walk) finding the
//! minimum in few steps.

use super::*;
use crate::back::wgsl::buffer::tests::{walk, words};
use crate::scene::MaterialId;

fn sphere(x: f64, k: usize) -> Instance {
    let quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    Instance {
        shape: Node::Sphere { radius: 0.5 },
        offset: [x, 0.0, 0.0],
        rotation: (k % 3 == 1).then_some(quarter),
        material: (k % 2 == 0).then_some(MaterialId(k as u32)),
        aabb: ([x - 0.5, -0.5, -0.5], [x + 0.5, 0.5, 0.5]),
    }
}

/// Every instance is written once with its flags and material, every group's `next` lies
/// past its own entries and within the data, and stepping by each entry's size (as
/// `instance_size` does) ends exactly at `end`.
#[test]
fn entries_cover_every_instance_and_groups_skip_forward() {
    let instances: Vec<Instance> = (0..41).map(|k| sphere(k as f64 * 1.5, k)).collect();
    let e = words(&data(&instances).bytes);
    let mut seen = Vec::new();
    let groups = walk(&e, |i, tag| {
        let x = f32::from_bits(e[i][0]);
        let k = (x / 1.5).round() as usize;
        assert_eq!(tag & KIND_BITS, SPHERE);
        assert_eq!(tag & ROTATED != 0, k % 3 == 1, "instance {k}");
        let material = if k % 2 == 0 { k as u32 } else { 0 };
        assert_eq!(tag >> MATERIAL_SHIFT, material);
        seen.push(k);
        2 + 3 * usize::from(tag & ROTATED != 0)
    });
    assert!(groups >= 9, "{groups} groups");
    seen.sort_unstable();
    assert_eq!(seen, (0..41).collect::<Vec<_>>());
}

fn box_of(a: [f32; 3]) -> f32 {
    let m = a.map(|x| x.max(0.0));
    ((m[0] * m[0] + m[1] * m[1]) + m[2] * m[2]).sqrt() + a[0].max(a[1].max(a[2])).min(0.0)
}

/// What [`model`] found: the minimum and its instance (0: start), for `walk_sdf` the
/// nearest instance evaluated (its key) and the bound on every other instance, and the
/// work done: instances evaluated, boxes measured, the deepest stack.
struct Visit {
    best: f32,
    owner: usize,
    key: usize,
    bound: f32,
    evaluated: usize,
    boxes: usize,
    deepest: usize,
}

/// The distance at `p` of the unrotated sphere whose entry starts at `e[i]`.
fn sphere_at(e: &[[f32; 4]], i: usize, p: [f32; 3]) -> f32 {
    let q = [0, 1, 2].map(|k| p[k] - e[i][k]);
    ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]).sqrt() - e[i + 1][0]
}

/// The walk of `walk_map` (with `material`) or `walk_sdf` as the kernel does it, over the
/// entries `e` of unrotated spheres, the instance at `hint` first.
fn model(
    e: &[[f32; 4]],
    p: [f32; 3],
    start: f32,
    hint: usize,
    stack: usize,
    material: bool,
) -> Visit {
    let bits = |x: f32| x.to_bits() as usize;
    let group = |g: usize| {
        let (c, h) = (e[g], e[g + 1]);
        box_of([0, 1, 2].map(|k| (p[k] - c[k]).abs() - h[k]))
    };
    let farther = |x: f32, best: f32| if material { x > best } else { x >= best };
    let mut v = Visit {
        best: start,
        owner: 0,
        key: hint,
        bound: f32::INFINITY,
        evaluated: 0,
        boxes: 0,
        deepest: 0,
    };
    let mut kd = f32::INFINITY;
    if hint != 0 {
        v.evaluated += 1;
        kd = sphere_at(e, hint, p);
        if kd < v.best {
            (v.best, v.owner) = (kd, hint);
        }
    }
    let mut st: Vec<(usize, f32)> = Vec::new();
    let (mut i, mut stop) = (1, bits(e[0][0]));
    if bits(e[1][3]) == GROUP as usize {
        st.push((1, group(1)));
        v.boxes += 1;
        i = stop;
    }
    loop {
        if i < stop {
            let d = sphere_at(e, i, p);
            v.evaluated += 1;
            if d < v.best || (material && d == v.best && i < v.owner) {
                (v.best, v.owner) = (d, i);
            }
            if d < kd {
                v.bound = v.bound.min(kd);
                (kd, v.key) = (d, i);
            } else if i != v.key {
                v.bound = v.bound.min(d);
            }
            i += 2;
            continue;
        }
        let Some((mut g, near)) = st.pop() else { break };
        if farther(near, v.best) {
            v.bound = v.bound.min(near);
            continue;
        }
        loop {
            let a = g + 2;
            if bits(e[a][3]) != GROUP as usize {
                (i, stop) = (a, bits(e[g + 1][3]));
                break;
            }
            let b = bits(e[a + 1][3]);
            let (da, db) = (group(a), group(b));
            v.boxes += 2;
            let (n, f) = if da <= db { (a, b) } else { (b, a) };
            if !farther(da.max(db), v.best) {
                st.push((f, da.max(db)));
                v.deepest = v.deepest.max(st.len());
                assert!(st.len() <= stack, "stack of {stack} overflows");
            } else {
                v.bound = v.bound.min(da.max(db));
            }
            if farther(da.min(db), v.best) {
                v.bound = v.bound.min(da.min(db));
                break;
            }
            g = n;
        }
    }
    v
}

/// The cache of `sdf`'s last walk: its key, its point, its bound.
type Cache = (usize, [f32; 3], f32);

/// `sdf` as the kernel has it: the cache of the last walk (hint, its point, its bound)
/// when it suffices, else the walk, which renews the cache. Adds to `walks` and `boxes`.
fn model_sdf(
    e: &[[f32; 4]],
    p: [f32; 3],
    start: f32,
    cache: &mut Cache,
    stack: usize,
    walks: &mut usize,
    boxes: &mut usize,
) -> f32 {
    let (hint, at, bound) = *cache;
    if hint != 0 {
        let d = start.min(sphere_at(e, hint, p));
        let q = [0, 1, 2].map(|k| p[k] - at[k]);
        if d <= bound - ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]).sqrt() {
            return d;
        }
    }
    let v = model(e, p, start, hint, stack, false);
    *walks += 1;
    *boxes += v.boxes;
    if v.key != 0 {
        *cache = (v.key, p, v.bound);
    }
    v.best
}

/// The vectors of `scene_data` as floats.
fn vectors(d: &Data) -> Vec<[f32; 4]> {
    words(&d.bytes)
        .into_iter()
        .map(|v| v.map(f32::from_bits))
        .collect()
}

/// The minimum of `start` and every sphere of `e` in `scene_data`'s order, and its entry
/// (0: start).
fn brute(e: &[[f32; 4]], p: [f32; 3], start: f32) -> (f32, usize) {
    let end = e[0][0].to_bits() as usize;
    let (mut best, mut owner, mut i) = (start, 0, 1);
    while i < end {
        if e[i][3].to_bits() != GROUP {
            let d = sphere_at(e, i, p);
            if d < best {
                (best, owner) = (d, i);
            }
        }
        i += 2;
    }
    (best, owner)
}

/// The nearest-first walk finds the same minimum as every instance in `scene_data`'s
/// order (the same value, and with the material, the same instance on a tie, the rest
/// first) whatever its hint, its stack never holds more than the hierarchy's depth, and
/// near the surface of 4 096 spheres it evaluates a few of them, and no more boxes with
/// the nearest instance as its hint.
#[test]
fn the_nearest_first_walk_finds_the_minimum_in_few_steps() {
    let mut rng = crate::rng::Rng::new(7);
    let mut instances = Vec::new();
    for k in 0..4096 {
        let c = [(k % 16) as f64, ((k / 16) % 16) as f64, (k / 256) as f64]
            .map(|x| x * 1.5 + rng.range(-0.2, 0.2));
        let r = rng.range(0.2, 0.6);
        instances.push(Instance {
            shape: Node::Sphere { radius: r },
            offset: c,
            rotation: None,
            material: Some(MaterialId(k)),
            aabb: (c.map(|x| x - r), c.map(|x| x + r)),
        });
    }
    // Two copies in one place: their distances tie everywhere.
    instances.push(Instance {
        material: Some(MaterialId(9999)),
        ..instances[700].clone()
    });
    let d = data(&instances);
    let e = vectors(&d);
    assert!((10..=12).contains(&d.stack), "depth {}", d.stack);
    let brute = |p: [f32; 3], start: f32| brute(&e, p, start);
    let end = e[0][0].to_bits() as usize;
    // Every vector is a group's two or an unrotated sphere's two.
    let entries: Vec<usize> = (1..end)
        .step_by(2)
        .filter(|&i| e[i][3].to_bits() != GROUP)
        .collect();
    let (mut near_surface, mut deepest, mut ties) = (0, 0, 0);
    let (mut evaluated, mut boxes, mut hinted_boxes) = (0, 0, 0);
    for n in 0..3000 {
        let p = if n % 3 == 0 {
            // On the surface of a sphere, at some copies' exact distance.
            let c = instances[if n % 2 == 0 { 700 } else { rng.below(4096) }].offset;
            c.map(|x| (x + rng.range(-0.7, 0.7)) as f32)
        } else {
            [0, 1, 2].map(|_| rng.range(-4.0, 26.0) as f32)
        };
        for start in [f32::INFINITY, 0.3, 2.0] {
            let (want, owner) = brute(p, start);
            let nearest = brute(p, f32::INFINITY).1;
            let stray = entries[rng.below(entries.len())];
            for hint in [0, nearest, stray] {
                let v = model(&e, p, start, hint, d.stack, false);
                assert_eq!(v.best.to_bits(), want.to_bits(), "{p:?} hint {hint}");
                // Every instance but the key is at least as far as the bound.
                for &j in entries.iter().filter(|&&j| j != v.key) {
                    assert!(
                        sphere_at(&e, j, p) >= v.bound,
                        "{p:?} {hint}: {j} {}",
                        v.bound
                    );
                }
                let Visit {
                    best: map,
                    owner: who,
                    evaluated: k,
                    boxes: b,
                    deepest: s,
                    ..
                } = model(&e, p, start, hint, d.stack, true);
                assert_eq!(
                    (map.to_bits(), who),
                    (want.to_bits(), owner),
                    "{p:?} {hint}"
                );
                deepest = deepest.max(s);
                let twin = instances[700].offset.map(|x| x as f32);
                ties += usize::from(who != 0 && e[who][0..3] == twin);
                if start.is_infinite() && want.abs() < 0.1 {
                    if hint == 0 {
                        near_surface += 1;
                        evaluated += k;
                        boxes += b;
                    } else if hint == nearest {
                        hinted_boxes += b;
                    }
                }
            }
        }
    }
    assert!(
        deepest <= d.stack && deepest >= d.stack - 2,
        "deepest {deepest}"
    );
    assert!(near_surface > 100, "{near_surface} points near a surface");
    assert!(ties > 100, "{ties} ties");
    let per = |x: usize| x as f64 / near_surface as f64;
    println!(
        "{near_surface} points near a surface: {:.1} instances and {:.1} boxes each, {:.1} \
         boxes with the nearest as the hint; stack {deepest} of {}",
        per(evaluated),
        per(boxes),
        per(hinted_boxes),
        d.stack
    );
    assert!(
        per(evaluated) < 16.0,
        "{} instances evaluated per point near a surface",
        per(evaluated)
    );
    assert!(
        hinted_boxes <= boxes,
        "{hinted_boxes} boxes hinted, {boxes} not"
    );
}

/// Camera rays, their normals' taps and shadow rays marched through 1 024 jittered
/// spheres over a plane (examples/scaling/jittered_1024.sdf) with `sdf`'s cache: every
/// step's distance is the minimum over every instance, bit for bit, and most steps need
/// no walk.
#[test]
fn the_cache_of_the_last_walk_gives_the_minimum_and_spares_most_walks() {
    let mut rng = crate::rng::Rng::new(11);
    let instances: Vec<Instance> = (0..1024)
        .map(|k| {
            let cell = [k % 16, k / 64, k / 16 % 4];
            let c = [0, 1, 2].map(|a| {
                let centre = if a == 1 { 0.5 } else { -7.5 };
                (cell[a] as f64 + centre) * 0.5 + rng.range(-0.1, 0.1)
            });
            let r = 0.15;
            Instance {
                shape: Node::Sphere { radius: r },
                offset: c,
                rotation: None,
                material: None,
                aabb: (c.map(|x| x - r), c.map(|x| x + r)),
            }
        })
        .collect();
    let d = data(&instances);
    let e = vectors(&d);
    let norm = |v: [f32; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    let (mut steps, mut walks, mut boxes, mut uncached_boxes) = (0, 0, 0, 0);
    let mut cache = (0, [0.0; 3], 0.0);
    let mut field = |p: [f32; 3], cache: &mut Cache| {
        let start = p[1];
        let got = model_sdf(&e, p, start, cache, d.stack, &mut walks, &mut boxes);
        assert_eq!(got.to_bits(), brute(&e, p, start).0.to_bits(), "{p:?}");
        uncached_boxes += model(&e, p, start, cache.0, d.stack, false).boxes;
        steps += 1;
        got
    };
    let (eye, light) = ([0.0f32, 3.2, -7.5], norm([0.5, 1.0, -0.6]));
    let mut hits = 0;
    for y in 0..24 {
        for x in 0..32 {
            let target = [(x as f32 - 15.5) * 0.25, 3.0 - y as f32 * 0.2, 0.0];
            let dir = norm([0, 1, 2].map(|k| target[k] - eye[k]));
            let Some(p) = march(&mut field, eye, dir, &mut cache) else {
                continue;
            };
            hits += 1;
            // The normal's taps, then a shadow ray from just above the surface.
            let h = 1e-3;
            let g = [0, 1, 2].map(|k| {
                let (mut a, mut b) = (p, p);
                a[k] += h;
                b[k] -= h;
                field(a, &mut cache) - field(b, &mut cache)
            });
            let n = norm(g);
            let o = [0, 1, 2].map(|k| p[k] + n[k] * 2e-3);
            march(&mut field, o, light, &mut cache);
        }
    }
    assert!(hits > 500, "{hits} hits");
    let per = |x: usize| x as f64 / steps as f64;
    println!(
        "{steps} steps: {:.2} walks and {:.2} boxes each ({:.2} boxes walking every step)",
        per(walks),
        per(boxes),
        per(uncached_boxes)
    );
    assert!(per(walks) < 0.5, "{:.2} walks a step", per(walks));
}

/// The point where a ray from `o` along `dir` first comes within 1e-4·t of the surface,
/// marched through `field` with `cache`, if it does within 512 steps and 30 units.
fn march(
    field: &mut impl FnMut([f32; 3], &mut Cache) -> f32,
    o: [f32; 3],
    dir: [f32; 3],
    cache: &mut Cache,
) -> Option<[f32; 3]> {
    let mut t = 0.0f32;
    for _ in 0..512 {
        let p = [0, 1, 2].map(|k| o[k] + t * dir[k]);
        let d = field(p, cache);
        if d < 1e-4 * t.max(1.0) {
            return Some(p);
        }
        t += d;
        if t > 30.0 {
            break;
        }
    }
    None
}
