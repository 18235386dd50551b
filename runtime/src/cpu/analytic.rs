//! Analytic ray tracing on the CPU: the closed-form intersections of the primitives that
//! `sdfc_compiler::analytic` found (spheres, planes, boxes, capped cylinders and
//! capsules under affine maps), nearest hits with exact normals, and any-hit shadow rays.
//!
//! Every primitive but a mesh is convex (a plane bounds a half-space), so a ray meets it in
//! one interval [near, far]; the hit is the first end of an interval beyond the ray's origin.
//! A mesh's hit is its nearest triangle crossing, found through its hierarchy (as the WGSL
//! kernel's `mesh_interval`, compiler/src/back/wgsl/mesh.rs), an interval of one point. Rays start
//! on the surface offset along the normal (as in sphere tracing), so t = 0 is the origin.

use super::vec::V3;
use sdfc_compiler::{
    analytic::{Item, MeshRef, Primitive, Shape, Traced},
    Float,
};

/// A primitive in the evaluation type.
#[derive(Debug, Clone, Copy)]
enum Kind<T> {
    Sphere {
        r2: T,
    },
    Box {
        half: V3<T>,
    },
    Cylinder {
        r2: T,
        half_height: T,
    },
    Capsule {
        r2: T,
        half_height: T,
    },
    Plane {
        normal: V3<T>,
        height: T,
    },
    /// The mesh of the tracer's `meshes` at this index.
    Mesh {
        index: usize,
    },
}

#[derive(Debug, Clone, Copy)]
struct Prim<T> {
    kind: Kind<T>,
    /// Rows of the world-to-local matrix.
    rows: [V3<T>; 3],
    offset: V3<T>,
    material: u32,
}

/// The part of a ray inside a primitive, with the outward normals (local frame) at its ends.
#[derive(Debug, Clone, Copy)]
struct Interval<T> {
    near: T,
    far: T,
    n_near: V3<T>,
    n_far: V3<T>,
}

/// A ray's nearest surface.
#[derive(Debug, Clone, Copy)]
pub(super) struct Surface<T> {
    pub t: T,
    /// Unit outward normal in world space.
    pub normal: V3<T>,
    pub material: u32,
}

/// An entry of the hierarchy (`sdfc_compiler::analytic::hierarchy`).
#[derive(Debug, Clone)]
enum Node<T> {
    Prim(usize),
    /// A world-space box (centre, half-extents) around the nodes in it.
    Group {
        centre: V3<T>,
        half: V3<T>,
        items: Vec<Node<T>>,
    },
}

fn node<T: Float>(item: &Item) -> Node<T> {
    match item {
        Item::Primitive(i) => Node::Prim(*i),
        Item::Group(g) => Node::Group {
            centre: V3::from_f64(g.centre),
            half: V3::from_f64(g.half),
            items: g.items.iter().map(node).collect(),
        },
    }
}

/// The primitives of an analytically traced scene and their hierarchy.
#[derive(Debug, Clone)]
pub(super) struct Tracer<T> {
    prims: Vec<Prim<T>>,
    top: Vec<Node<T>>,
    meshes: Vec<MeshRef>,
}

/// Whether a ray meets a group's box between 0 and `limit`.
fn enters<T: Float>(o: V3<T>, d: V3<T>, centre: V3<T>, half: V3<T>, limit: T) -> bool {
    boxed(o - centre, d, half)
        .is_some_and(|s| s.near <= s.far && s.far > T::zero() && s.near < limit)
}

impl<T: Float> Tracer<T> {
    /// The tracer of `traced`'s primitives, walked through its hierarchy.
    pub fn new(traced: &Traced) -> Self {
        let f = T::from_f64;
        let prims = traced
            .primitives
            .iter()
            .map(|p| Prim {
                kind: match p.shape {
                    Shape::Sphere { radius } => Kind::Sphere {
                        r2: f(radius * radius),
                    },
                    Shape::Box { half } => Kind::Box {
                        half: V3::from_f64(half),
                    },
                    Shape::Cylinder {
                        radius,
                        half_height,
                    } => Kind::Cylinder {
                        r2: f(radius * radius),
                        half_height: f(half_height),
                    },
                    Shape::Capsule {
                        radius,
                        half_height,
                    } => Kind::Capsule {
                        r2: f(radius * radius),
                        half_height: f(half_height),
                    },
                    Shape::Plane { normal, height } => Kind::Plane {
                        normal: V3::from_f64(normal),
                        height: f(height),
                    },
                    Shape::Mesh { index, .. } => Kind::Mesh {
                        index: index as usize,
                    },
                },
                rows: p.matrix.map(V3::from_f64),
                offset: V3::from_f64(p.offset),
                material: p.material.0,
            })
            .collect();
        let top = traced.hierarchy.iter().map(node).collect();
        Tracer {
            prims,
            top,
            meshes: traced.meshes.clone(),
        }
    }

    /// Visits the primitives of `nodes` whose groups the ray enters before `limit` (which
    /// `f` may lower as it goes); stops when `f` returns false.
    fn visit(
        &self,
        nodes: &[Node<T>],
        o: V3<T>,
        d: V3<T>,
        limit: &mut T,
        f: &mut impl FnMut(&Prim<T>, &mut T) -> bool,
    ) -> bool {
        for n in nodes {
            let go_on = match n {
                Node::Prim(i) => f(&self.prims[*i], limit),
                Node::Group {
                    centre,
                    half,
                    items,
                } => !enters(o, d, *centre, *half, *limit) || self.visit(items, o, d, limit, f),
            };
            if !go_on {
                return false;
            }
        }
        true
    }

    /// The nearest surface along `o + t·d` with 0 < t < `tmax`, the distance of a surface of
    /// material `m` counted `slack(m)` farther. Inside glass, the caller gives transparent
    /// surfaces the offset of secondary rays as slack, so that an opaque surface that
    /// coincides with the glass's far side (a glass box standing on the floor) is the one
    /// met, rather than a refracted ray leaving the glass from within the floor.
    pub fn nearest(
        &self,
        o: V3<T>,
        d: V3<T>,
        tmax: T,
        slack: impl Fn(u32) -> T,
    ) -> Option<Surface<T>> {
        let mut best: Option<(T, V3<T>, Prim<T>)> = None;
        let mut limit = tmax;
        self.visit(&self.top, o, d, &mut limit, &mut |p, limit| {
            let Some(s) = p.interval(o, d, *limit, &self.meshes) else {
                return true;
            };
            let (t, n) = if s.near > T::zero() {
                (s.near, s.n_near)
            } else {
                (s.far, s.n_far)
            };
            let key = t + slack(p.material);
            if t > T::zero() && key < *limit {
                *limit = key;
                best = Some((t, n, *p));
            }
            true
        });
        best.map(|(t, n, p)| Surface {
            t,
            normal: p.to_world(n),
            material: p.material,
        })
    }

    /// The fraction of light that passes along `o + t·d` for 0 < t < `tmax`: 0 when an opaque
    /// primitive is in the way, else the product of the transparencies of the primitives whose
    /// surface the ray crosses (`transparency` of a material id): those it enters, and the
    /// glass it starts inside of (from an opaque surface within glass), whose far side it
    /// crosses.
    pub fn transmitted(&self, o: V3<T>, d: V3<T>, tmax: T, transparency: impl Fn(u32) -> T) -> T {
        let mut through = T::one();
        let mut limit = tmax;
        self.visit(&self.top, o, d, &mut limit, &mut |p, _| {
            let Some(s) = p.interval(o, d, tmax, &self.meshes) else {
                return true;
            };
            if !(s.far > T::zero() && s.near < tmax) {
                return true;
            }
            let tau = transparency(p.material);
            if tau <= T::zero() {
                through = T::zero();
                return false;
            }
            through = through * tau;
            true
        });
        through
    }
}

/// The most heap bytes making and holding a [`Tracer`] for `scene` takes (none when the scene
/// is sphere traced): its primitives and the nodes of its hierarchy (fewer than two per
/// primitive), and, while it is built, the compiler's list of primitives, their boxes and its
/// tree (counted four times over, with 256 bytes per primitive for the vectors' slack).
pub(super) fn heap_bytes<T: Float>(
    scene: &sdfc_compiler::Scene,
    traceable: &sdfc_compiler::analytic::Traceable,
) -> u64 {
    use std::mem::size_of;
    let n = traceable
        .traced(scene.settings.method)
        .map_or(0, |t| t.primitives.len()) as u64;
    let held = size_of::<Prim<T>>() + 2 * size_of::<Node<T>>();
    let building = 4 * size_of::<Primitive>() + 256;
    n * (held + building) as u64
}

impl<T: Float> Prim<T> {
    fn local(&self, v: V3<T>) -> V3<T> {
        V3::new(
            self.rows[0].dot(v),
            self.rows[1].dot(v),
            self.rows[2].dot(v),
        )
    }

    /// A local normal in world space: normals map by the transpose of the world-to-local
    /// matrix (the inverse transpose of the local-to-world one).
    fn to_world(self, n: V3<T>) -> V3<T> {
        (self.rows[0] * n.x + self.rows[1] * n.y + self.rows[2] * n.z).normalize()
    }

    /// The ray's interval inside the primitive, or `None` when it misses (a mesh's crossing
    /// is searched for before `limit` alone).
    fn interval(&self, o: V3<T>, d: V3<T>, limit: T, meshes: &[MeshRef]) -> Option<Interval<T>> {
        let (o, d) = (self.local(o) + self.offset, self.local(d));
        let s = match self.kind {
            Kind::Sphere { r2 } => sphere(o, d, r2)?,
            Kind::Box { half } => boxed(o, d, half)?,
            Kind::Cylinder { r2, half_height } => cylinder(o, d, r2, half_height)?,
            Kind::Capsule { r2, half_height } => capsule(o, d, r2, half_height)?,
            Kind::Plane { normal, height } => plane(o, d, normal, height)?,
            Kind::Mesh { index } => {
                let (t, n) = super::mesh_hit::crossing(&meshes[index].0, o, d, limit)?;
                Interval {
                    near: t,
                    far: t,
                    n_near: n,
                    n_far: n,
                }
            }
        };
        (s.near <= s.far).then_some(s)
    }
}

fn inf<T: Float>() -> T {
    T::from_f64(f64::INFINITY)
}

/// Roots of |o + t·d|² = r².
fn sphere<T: Float>(o: V3<T>, d: V3<T>, r2: T) -> Option<Interval<T>> {
    let a = d.dot(d);
    let b = o.dot(d);
    let c = o.dot(o) - r2;
    let disc = b * b - a * c;
    if !(disc >= T::zero()) {
        return None;
    }
    let q = disc.sqrt();
    let (near, far) = ((-b - q) / a, (-b + q) / a);
    Some(Interval {
        near,
        far,
        n_near: o + d * near,
        n_far: o + d * far,
    })
}

/// One slab |x| <= h along an axis: the entry and exit (None when the ray runs parallel
/// outside it; infinite ends when parallel inside).
fn slab<T: Float>(o: T, d: T, h: T) -> Option<(T, T)> {
    if d == T::zero() {
        return (o.abs() <= h).then(|| (-inf::<T>(), inf::<T>()));
    }
    let inv = T::one() / d;
    let (t1, t2) = ((-h - o) * inv, (h - o) * inv);
    Some((t1.min(t2), t1.max(t2)))
}

/// The unit vector along `axis` pointing with `s` (+1 or -1).
fn axis<T: Float>(axis: usize, s: T) -> V3<T> {
    let mut v = [T::zero(); 3];
    v[axis] = s;
    V3::new(v[0], v[1], v[2])
}

fn sign<T: Float>(x: T) -> T {
    if x < T::zero() {
        -T::one()
    } else {
        T::one()
    }
}

/// The intersection of the three slabs (Kay and Kajiya); the normal is the face of the slab
/// entered last (near) or left first (far).
fn boxed<T: Float>(o: V3<T>, d: V3<T>, half: V3<T>) -> Option<Interval<T>> {
    let (o, d, h) = ([o.x, o.y, o.z], [d.x, d.y, d.z], [half.x, half.y, half.z]);
    let mut s = Interval {
        near: -inf::<T>(),
        far: inf::<T>(),
        n_near: V3::zero(),
        n_far: V3::zero(),
    };
    for i in 0..3 {
        let (a, b) = slab(o[i], d[i], h[i])?;
        if a > s.near {
            s.near = a;
            s.n_near = axis(i, -sign(d[i]));
        }
        if b < s.far {
            s.far = b;
            s.n_far = axis(i, sign(d[i]));
        }
    }
    Some(s)
}

/// The infinite cylinder x² + z² <= r² cut by the slab |y| <= h.
fn cylinder<T: Float>(o: V3<T>, d: V3<T>, r2: T, h: T) -> Option<Interval<T>> {
    let a = d.x * d.x + d.z * d.z;
    let b = o.x * d.x + o.z * d.z;
    let c = o.x * o.x + o.z * o.z - r2;
    let (mut near, mut far) = if a == T::zero() {
        if c > T::zero() {
            return None;
        }
        (-inf::<T>(), inf::<T>())
    } else {
        let disc = b * b - a * c;
        if !(disc >= T::zero()) {
            return None;
        }
        let q = disc.sqrt();
        ((-b - q) / a, (-b + q) / a)
    };
    let side = |t: T| V3::new(o.x + d.x * t, T::zero(), o.z + d.z * t);
    let (mut n_near, mut n_far) = (side(near), side(far));
    let (y0, y1) = slab(o.y, d.y, h)?;
    if y0 > near {
        near = y0;
        n_near = axis(1, -sign(d.y));
    }
    if y1 < far {
        far = y1;
        n_far = axis(1, sign(d.y));
    }
    Some(Interval {
        near,
        far,
        n_near,
        n_far,
    })
}

/// The capsule: the convex hull of two spheres at y = ±h, which is the union of them and the
/// capped cylinder between them, so the ray's interval is the hull of the three intervals.
/// The normals point away from the nearest point of the segment.
fn capsule<T: Float>(o: V3<T>, d: V3<T>, r2: T, h: T) -> Option<Interval<T>> {
    let up = V3::new(T::zero(), h, T::zero());
    let parts = [
        sphere(o - up, d, r2),
        sphere(o + up, d, r2),
        cylinder(o, d, r2, h),
    ];
    let (mut near, mut far) = (inf::<T>(), -inf::<T>());
    for s in parts.into_iter().flatten().filter(|s| s.near <= s.far) {
        near = near.min(s.near);
        far = far.max(s.far);
    }
    if !(near <= far) {
        return None;
    }
    let normal = |t: T| {
        let p = o + d * t;
        V3::new(p.x, p.y - p.y.clamp(-h, h), p.z)
    };
    Some(Interval {
        near,
        far,
        n_near: normal(near),
        n_far: normal(far),
    })
}

/// The half-space dot(p, n) <= h.
fn plane<T: Float>(o: V3<T>, d: V3<T>, n: V3<T>, h: T) -> Option<Interval<T>> {
    let dn = n.dot(d);
    let above = n.dot(o) - h;
    if dn == T::zero() {
        return (above <= T::zero()).then_some(Interval {
            near: -inf::<T>(),
            far: inf::<T>(),
            n_near: n,
            n_far: n,
        });
    }
    let t = -above / dn;
    let (near, far) = if dn > T::zero() {
        (-inf::<T>(), t)
    } else {
        (t, inf::<T>())
    };
    Some(Interval {
        near,
        far,
        n_near: n,
        n_far: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sdfc_compiler::analytic::traceable;
    use sdfc_compiler::eval_point;
    use sdfc_compiler::lower;
    use sdfc_compiler::Rng;

    /// A vector uniform in [-1, 1)³.
    fn v3(rng: &mut Rng) -> V3<f64> {
        let [x, y, z] = rng.point(1.0);
        V3::new(x, y, z)
    }

    /// Each shape, alone and under rotations and scales: along random rays, the traced hit
    /// lies on the zero set of the distance program with the program's gradient as its normal
    /// and material, and the field is positive between the origin and the hit (no nearer
    /// surface was missed); a ray reported to miss never comes near a surface.
    #[test]
    fn hits_lie_on_the_distance_fields_surface() {
        let shapes = [
            "sphere(0.8)",
            "box((0.5, 0.3, 0.7))",
            "cylinder(0.4, 0.6)",
            "plane((0.3, 1, 0.2), -0.5)",
            "box((0.5, 0.3, 0.7)).rotate_y(30deg).rotate_x(-20deg).translate(0.2, 0.1, -0.3)",
            "cylinder(0.4, 0.6).rotate_z(70deg).scale(1.3).translate(-0.2, 0, 0.1)",
            "sphere(0.5).scale((1.6, 0.5, 1)).rotate_y(40deg)",
            "box((0.4, 0.4, 0.4)).scale((1, 2, 0.5)).rotate_x(15deg)",
            "capsule(0.3, 0.8)",
            "capsule(0.4, 1.2).rotate_z(60deg).scale((1.2, 0.8, 1)).translate(0.1, 0.2, 0)",
        ];
        for shape in shapes {
            let text = format!(
                "material a = phong {{ color: (1, 0, 0) }};\nscene {{ {shape} @ a; sphere(0.3).translate(2, 0, 0); }}"
            );
            let (scene, diags, _) = sdfc_compiler::check_str("t.sdf", &text);
            let scene = scene.unwrap_or_else(|| panic!("{shape}: {diags:?}"));
            let traceable = traceable(&scene);
            let tracer =
                Tracer::<f64>::new(traceable.traced(scene.settings.method).expect("traced"));
            let program = lower(&scene);
            let f = |p: V3<f64>| eval_point::<f64>(&program, [p.x, p.y, p.z]);
            let mut rng = Rng::new(0x9e3779b97f4a7c15);
            let (mut hits, mut misses) = (0, 0);
            for _ in 0..2000 {
                let o = v3(&mut rng) * 3.0;
                if f(o).0 <= 1e-3 {
                    continue; // rays start outside every solid
                }
                let d = (v3(&mut rng) * 0.6 - o * 0.3).normalize();
                match tracer.nearest(o, d, 50.0, |_| 0.0) {
                    Some(s) => {
                        hits += 1;
                        let p = o + d * s.t;
                        let (dist, mat) = f(p);
                        assert!(dist.abs() < 1e-9, "{shape}: f = {dist} at the hit");
                        let h = 1e-6;
                        let g = V3::new(
                            f(p + V3::new(h, 0.0, 0.0)).0 - f(p - V3::new(h, 0.0, 0.0)).0,
                            f(p + V3::new(0.0, h, 0.0)).0 - f(p - V3::new(0.0, h, 0.0)).0,
                            f(p + V3::new(0.0, 0.0, h)).0 - f(p - V3::new(0.0, 0.0, h)).0,
                        );
                        // At an edge the gradient is not defined; away from edges the two agree.
                        if g.length() > 1.5e-6 {
                            let cos = g.normalize().dot(s.normal);
                            assert!(cos > 0.999, "{shape}: normal off by acos {cos} at {p:?}");
                        }
                        assert_eq!(mat, s.material, "{shape}: material at {p:?}");
                        for k in 1..64 {
                            let q = o + d * (s.t * k as f64 / 64.0);
                            assert!(f(q).0 > -1e-9, "{shape}: inside a solid before the hit");
                        }
                    }
                    None => {
                        misses += 1;
                        for k in 0..256 {
                            let q = o + d * (50.0 * k as f64 / 256.0);
                            assert!(f(q).0 > -1e-9, "{shape}: a missed ray passes a solid");
                        }
                    }
                }
            }
            assert!(
                hits > 100 && misses > 100,
                "{shape}: {hits} hits, {misses} misses"
            );
        }
    }

    /// Shadow rays: blocked by an opaque primitive between the ends, passing the transparency
    /// of a transparent one, unaffected by primitives beyond `tmax` or behind the origin.
    #[test]
    fn shadow_rays_see_occluders_between_their_ends() {
        let text = "material glass = phong { transparency: 0.5, ior: 1.5 };\n\
                    scene { sphere(1).translate(0, 0, 5); sphere(1).translate(0, 0, -5) @ glass; }";
        let (scene, _, _) = sdfc_compiler::check_str("t.sdf", text);
        let scene = scene.expect("checks");
        let traceable = traceable(&scene);
        let tracer = Tracer::<f64>::new(traceable.traced(scene.settings.method).expect("traced"));
        let tau = |m: u32| if m == 1 { 0.5 } else { 0.0 };
        let (o, fwd, back) = (V3::zero(), V3::new(0.0, 0.0, 1.0), V3::new(0.0, 0.0, -1.0));
        assert_eq!(tracer.transmitted(o, fwd, 10.0, tau), 0.0);
        assert_eq!(tracer.transmitted(o, fwd, 3.9, tau), 1.0);
        assert_eq!(tracer.transmitted(o, back, 10.0, tau), 0.5);
        let side = V3::new(1.0, 0.0, 0.0);
        assert_eq!(tracer.transmitted(o, side, 10.0, tau), 1.0);
    }

    /// The hierarchy skips only what cannot be hit: on a scene of 300 scattered primitives,
    /// every ray finds the same nearest hit as testing every primitive, and the same light.
    #[test]
    fn the_hierarchy_finds_what_testing_everything_finds() {
        // Material 1 is opaque in the scene (overlapping glass is not traced), but the test's
        // `tau` treats it as transparent, which is all `transmitted` looks at.
        let mut text =
            String::from("material glass = phong { reflect: 0.5 };\nscene {\n plane();\n");
        let mut rng = Rng::new(0x2545f4914f6cdd1d);
        for i in 0..300 {
            let (x, y, z) = (
                rng.range(-8.0, 8.0),
                rng.range(0.0, 6.0),
                rng.range(-8.0, 8.0),
            );
            let shape = match i % 3 {
                0 => "sphere(0.3)",
                1 => "box((0.3, 0.1, 0.2)).rotate_y(25deg)",
                _ => "cylinder(0.2, 0.3).rotate_x(40deg)",
            };
            let paint = if i % 7 == 0 { " @ glass" } else { "" };
            text.push_str(&format!(" {shape}.translate({x}, {y}, {z}){paint};\n"));
        }
        text.push_str("}\n");
        let (scene, diags, _) = sdfc_compiler::check_str("t.sdf", &text);
        let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
        let traceable = traceable(&scene);
        let tracer = Tracer::<f64>::new(traceable.traced(scene.settings.method).expect("traced"));
        assert!(matches!(tracer.top.last(), Some(Node::Group { .. })));
        let brute = Tracer::<f64> {
            prims: tracer.prims.clone(),
            top: (0..tracer.prims.len()).map(Node::Prim).collect(),
            meshes: tracer.meshes.clone(),
        };
        let tau = |m: u32| if m == 1 { 0.5 } else { 0.0 };
        let mut hits = 0;
        for _ in 0..3000 {
            let o = v3(&mut rng) * 12.0 + V3::new(0.0, 6.0, 0.0);
            let d = v3(&mut rng).normalize();
            let slack = |m: u32| if m == 1 { 0.01 } else { 0.0 };
            let (a, b) = (
                tracer.nearest(o, d, 100.0, slack),
                brute.nearest(o, d, 100.0, slack),
            );
            assert_eq!(a.map(|s| (s.t, s.material)), b.map(|s| (s.t, s.material)));
            hits += usize::from(a.is_some());
            let (a, b) = (
                tracer.transmitted(o, d, 7.0, tau),
                brute.transmitted(o, d, 7.0, tau),
            );
            assert_eq!(a, b);
        }
        assert!(hits > 500, "{hits}");
    }
}
