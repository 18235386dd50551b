//! The hull of balls and of circles against references: the hull of equal balls
//! (`hull(points, radius)`), the round cone of two balls, the support function's max found by
//! enumeration, and no direction of a fine grid beating it.

use super::*;
use crate::prim::Args;
use crate::program::Float;
use crate::Rng;

fn run(prim: &Prim, args: &Args, at: [f64; 3]) -> f64 {
    let mut b = Builder::new(true);
    let p = b.input_point();
    let d = (prim.distance)(&mut b, p, args);
    let m = b.c(-1.0);
    let program = b.finish(d, m);
    let regs = program.run::<f64>(at, |_| {});
    regs[program.distance().0 as usize].to_f64()
}

fn of_balls(balls: &[Ball], at: [f64; 3]) -> f64 {
    run(&BALLS, &Args::with_list(&[], 0, &ball_entries(balls)), at)
}

/// max over unit u of f(u) = min_k (q_k·u − r_k), q_k = p − c_k, found by enumeration: f is a
/// minimum of linear functions, so its maximum on the sphere is at a stationary point of one
/// of them on the set where it ties with none, one or two others — the sphere, a circle on it
/// or two points. Every such point is tried (no pruning, no use of the hull's structure);
/// unit vectors only, so each value is at most the distance and the best is the distance.
fn reference(balls: &[Ball], p: DVec3) -> f64 {
    let q: Vec<DVec3> = balls.iter().map(|b| p - b.c).collect();
    let f = |u: DVec3| {
        q.iter()
            .zip(balls)
            .map(|(q, b)| q.dot(u) - b.r)
            .fold(f64::INFINITY, f64::min)
    };
    let mut best = f64::NEG_INFINITY;
    let mut try_u = |u: DVec3| {
        if u.is_finite() && (u.length() - 1.0).abs() < 1e-9 {
            best = best.max(f(u));
        }
    };
    for (i, qi) in q.iter().enumerate() {
        try_u(qi.normalize());
        for j in 0..q.len() {
            if j == i {
                continue;
            }
            // q_i·u = q_j·u + r_i − r_j: v·u = β.
            let v = *qi - q[j];
            let (vn, beta) = (v.normalize(), (balls[i].r - balls[j].r) / v.length());
            if beta.abs() > 1.0 {
                continue;
            }
            let w = (*qi - qi.dot(vn) * vn).normalize();
            let t = (1.0 - beta * beta).sqrt();
            try_u(beta * vn + t * w);
            try_u(beta * vn - t * w);
            for k in j + 1..q.len() {
                if k == i {
                    continue;
                }
                for u in tangent_planes(&balls[i], &balls[j], &balls[k]) {
                    try_u(u);
                }
            }
        }
    }
    best
}

/// The support function's max over 20000 directions spread over the sphere.
fn grid(balls: &[Ball], p: DVec3) -> f64 {
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..20000)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 20000.0;
            let (r, a) = ((1.0 - z * z).sqrt(), golden * i as f64);
            let u = DVec3::new(r * a.cos(), r * a.sin(), z);
            balls
                .iter()
                .map(|b| (p - b.c).dot(u) - b.r)
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// A ball of radius `r` centred at `c`.
fn ball(c: [f64; 3], r: f64) -> Ball {
    Ball {
        c: DVec3::from(c),
        r,
    }
}

/// The hull of `balls` against `prim` of `args` at `n` random points of the cube [lo, hi]³:
/// the same distance.
fn agree(
    rng: &mut Rng,
    balls: &[Ball],
    (prim, args): (&Prim, &Args),
    n: usize,
    (lo, hi): (f64, f64),
) {
    for _ in 0..n {
        let at = [0, 1, 2].map(|_| rng.range(lo, hi));
        let (ours, theirs) = (of_balls(balls, at), run(prim, args, at));
        assert!(
            (ours - theirs).abs() < 1e-9,
            "{at:?}: {ours} against {theirs}"
        );
    }
}

/// Balls of radius `r` at `centres` against the hull of the points `centres` grown by `r`, at
/// 300 random points of the cube [lo, hi]³.
fn agree_with_the_grown_hull(rng: &mut Rng, centres: &[[f64; 3]], r: f64, box_: (f64, f64)) {
    let balls: Vec<Ball> = centres.iter().map(|c| ball(*c, r)).collect();
    let points = Args::with_list(&[r], 0, centres);
    agree(
        rng,
        &balls,
        (&super::super::hull::PRIMS[0], &points),
        300,
        box_,
    );
}

#[test]
fn equal_balls_are_the_hull_of_their_centres_grown_by_the_radius() {
    let mut rng = Rng::new(3);
    for (count, r) in [(8, 0.3), (4, 0.5), (12, 0.1)] {
        let centres: Vec<[f64; 3]> = (0..count).map(|_| rng.point(1.0)).collect();
        agree_with_the_grown_hull(&mut rng, &centres, r, (-2.0, 2.0));
    }
    // Four balls in a plane: a rounded plate, its sides cylinders and its faces planes.
    let corners = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    agree_with_the_grown_hull(&mut rng, &corners, 0.25, (-1.0, 3.0));
}

#[test]
fn two_balls_are_the_round_cone_between_them() {
    let cone = super::super::between::PRIMS
        .iter()
        .find(|p| p.name == "round_cone")
        .expect("round_cone");
    let (a, b, ra, rb) = ([0.3, -0.2, 0.1], [1.5, 0.9, -0.4], 0.6, 0.2);
    let balls = [ball(a, ra), ball(b, rb)];
    let args = Args(vec![a, b, [ra, 0.0, 0.0], [rb, 0.0, 0.0]]);
    agree(&mut Rng::new(9), &balls, (cone, &args), 1000, (-2.0, 3.0));
}

#[test]
fn balls_of_any_radii_match_the_support_function_s_max_found_by_enumeration() {
    let mut rng = Rng::new(21);
    for case in 0..6 {
        let count = 2 + case;
        let mut balls: Vec<Ball> = (0..count)
            .map(|_| Ball {
                c: DVec3::from(rng.point(1.5)),
                r: rng.range(0.05, 0.8),
            })
            .collect();
        // One ball inside another changes nothing.
        balls.push(Ball {
            c: balls[0].c + DVec3::new(0.01, 0.0, 0.0),
            r: balls[0].r * 0.5,
        });
        assert!(outermost(&balls).len() < balls.len());
        for _ in 0..40 {
            let at = rng.point(3.0);
            let ours = of_balls(&balls, at);
            let search = reference(&balls, DVec3::from(at));
            assert!(ours >= grid(&balls, DVec3::from(at)) - 1e-12, "{at:?}");
            assert!(
                (ours - search).abs() < 1e-9,
                "case {case} at {at:?}: {ours} against {search}"
            );
        }
        // Points inside: the distance to the surface, negative.
        for b in &balls {
            let at = b.c.to_array();
            let ours = of_balls(&balls, at);
            let search = reference(&balls, b.c);
            assert!(
                ours < 0.0 && (ours - search).abs() < 1e-9,
                "{ours} {search}"
            );
        }
    }
}

#[test]
fn circles_match_the_support_function_s_max() {
    let mut rng = Rng::new(4);
    for count in 1..7 {
        let list: Vec<[f64; 3]> = (0..count)
            .map(|_| {
                [
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(0.05, 0.6),
                ]
            })
            .collect();
        let args = Args::with_list(&[], 0, &list);
        for _ in 0..60 {
            let at = [
                rng.range(-2.5, 2.5),
                rng.range(-2.5, 2.5),
                rng.range(-1.0, 1.0),
            ];
            let ours = run(&CIRCLES, &args, at);
            let q: Vec<(DVec2, f64)> = list
                .iter()
                .map(|c| (DVec2::new(at[0] - c[0], at[1] - c[1]), c[2]))
                .collect();
            let f = |u: DVec2| {
                q.iter()
                    .map(|(q, r)| q.dot(u) - r)
                    .fold(f64::INFINITY, f64::min)
            };
            // Where one circle's function is stationary, or two tie.
            let mut exact = f64::NEG_INFINITY;
            for (i, (qi, ri)) in q.iter().enumerate() {
                exact = exact.max(f(qi.normalize()));
                for (qj, rj) in &q[i + 1..] {
                    let v = *qi - *qj;
                    let beta = (ri - rj) / v.length();
                    if beta.abs() <= 1.0 {
                        let (vn, t) = (v.normalize(), (1.0 - beta * beta).sqrt());
                        exact = exact.max(f(beta * vn + t * vn.perp()));
                        exact = exact.max(f(beta * vn - t * vn.perp()));
                    }
                }
            }
            let mut grid = f64::NEG_INFINITY;
            for i in 0..20_000 {
                let t = std::f64::consts::TAU * i as f64 / 20_000.0;
                grid = grid.max(f(DVec2::new(t.cos(), t.sin())));
            }
            assert!(
                ours >= grid - 1e-12 && (ours - exact).abs() < 1e-9,
                "{count} circles at {at:?}: {ours} against {exact} (grid {grid})"
            );
        }
    }
}

#[test]
fn the_extent_holds_every_ball() {
    let balls = [
        Ball {
            c: DVec3::new(1.0, 2.0, 3.0),
            r: 0.5,
        },
        Ball {
            c: DVec3::new(-1.0, 0.0, 1.0),
            r: 1.0,
        },
    ];
    let e = (BALLS.extent)(&Args::with_list(&[], 0, &ball_entries(&balls)));
    assert_eq!((e.min, e.max), ([-2.0, -1.0, 0.0], [1.5, 2.5, 3.5]));
    let centre = DVec3::from(e.min).lerp(DVec3::from(e.max), 0.5);
    for b in &balls {
        assert!(b.c.distance(centre) + b.r <= e.radius + 1e-12);
    }
}

#[test]
fn degenerate_balls_stay_exact() {
    let ball = |c: [f64; 3], r: f64| Ball {
        c: DVec3::from(c),
        r,
    };
    let cases = [
        // On one line; one ball twice; points (radius 0) with a ball; four equal balls on a
        // circle (every three have the same two planes).
        vec![
            ball([0.0, 0.0, 0.0], 0.3),
            ball([1.0, 0.0, 0.0], 0.2),
            ball([2.0, 0.0, 0.0], 0.1),
        ],
        vec![
            ball([0.0, 0.0, 0.0], 0.4),
            ball([0.0, 0.0, 0.0], 0.4),
            ball([1.0, 0.5, 0.0], 0.2),
        ],
        vec![
            ball([0.0, 0.0, 0.0], 0.0),
            ball([1.0, 0.0, 0.0], 0.0),
            ball([0.0, 1.0, 0.0], 0.0),
            ball([0.0, 0.0, 1.0], 0.0),
            ball([0.3, 0.3, -1.0], 0.1),
        ],
        (0..4)
            .map(|i| {
                let a = i as f64 * std::f64::consts::FRAC_PI_2;
                ball([a.cos(), 0.0, a.sin()], 0.2)
            })
            .collect(),
    ];
    let mut rng = Rng::new(8);
    for balls in &cases {
        for _ in 0..200 {
            let at = rng.point(2.5);
            let ours = of_balls(balls, at);
            let exact = reference(balls, DVec3::from(at));
            assert!(
                ours.is_finite() && (ours - exact).abs() < 1e-9,
                "{balls:?} at {at:?}: {ours} against {exact}"
            );
        }
    }
}
