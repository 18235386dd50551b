//! A stable text dump of a scene (`sdfc compile --emit ir`, snapshot tests).

use super::ir::*;
use super::NodeId;
use crate::prim::Kind;
use std::fmt::Write;

/// Dumps a scene: settings, camera, lights, materials, then every node reachable from the root
/// as `%n = op(args)`, children before parents.
pub fn dump(scene: &Scene) -> String {
    let mut out = String::new();
    settings(&mut out, scene);
    lights(&mut out, scene);
    materials(&mut out, scene);
    match scene.root {
        None => out.push_str("root none\n"),
        Some(root) => {
            let mut order = Vec::new();
            let mut seen = vec![false; scene.graph.len()];
            postorder(&scene.graph, root, &mut seen, &mut order);
            for id in order {
                let _ = writeln!(out, "%{} = {}", id.0, node(scene.graph.node(id)));
            }
            let _ = writeln!(out, "root %{}", root.0);
        }
    }
    out
}

/// The render settings, the look, the origin and the camera.
fn settings(out: &mut String, scene: &Scene) {
    let s = &scene.settings;
    let _ = writeln!(
        out,
        "render {}x{} aa={} max_steps={} epsilon={} max_depth={} max_dist={} relaxation={} background={}",
        s.width, s.height, s.aa, s.max_steps, num(s.epsilon), s.max_depth, num(s.max_dist),
        num(s.relaxation), v3(s.background)
    );
    if s.footprint {
        let _ = writeln!(
            out,
            "epsilon follows the pixel footprint: {}",
            num(scene.epsilon())
        );
    }
    if s.method != Method::Auto {
        let _ = writeln!(out, "method {}", s.method.name());
    }
    if s.path {
        let _ = writeln!(
            out,
            "path traced: samples={} bounces={}",
            s.samples, s.bounces
        );
    }
    // The look, where a setting of it is on.
    if s.occlusion > 0.0 {
        let _ = writeln!(out, "occlusion {}", num(s.occlusion));
    }
    if s.fog > 0.0 {
        let colour = s.fog_color.map_or("the background".to_string(), v3);
        let _ = writeln!(out, "fog {} colour {colour}", num(s.fog));
    }
    if s.exposure != 0.0 || s.tonemap != crate::scene::Tonemap::None {
        let _ = writeln!(
            out,
            "exposure {} tonemap {}",
            num(s.exposure),
            s.tonemap.name()
        );
    }
    if scene.origin != [0.0; 3] {
        let _ = writeln!(
            out,
            "origin {} (moved to put the camera at the origin)",
            v3(scene.origin)
        );
    }
    let c = &scene.camera;
    let up = if c.up == Camera::default().up {
        String::new()
    } else {
        format!(" up={}", v3(c.up))
    };
    let _ = writeln!(
        out,
        "camera position={} look_at={}{up} fov={}deg",
        v3(c.position),
        v3(c.look_at),
        num(c.fov.to_degrees())
    );
}

/// One line for each light.
fn lights(out: &mut String, scene: &Scene) {
    for l in &scene.lights {
        let shadows = if l.shadows() { "" } else { " shadows=false" };
        let _ = match l {
            Light::Point {
                position,
                color,
                intensity,
                radius,
                penumbra,
                ..
            } => writeln!(
                out,
                "light point position={} color={} intensity={} radius={} penumbra={}deg{shadows}",
                v3(*position),
                v3(*color),
                num(*intensity),
                num(*radius),
                num(penumbra.to_degrees())
            ),
            Light::Directional {
                direction,
                color,
                intensity,
                penumbra,
                ..
            } => writeln!(
                out,
                "light directional direction={} color={} intensity={} penumbra={}deg{shadows}",
                v3(*direction),
                v3(*color),
                num(*intensity),
                num(penumbra.to_degrees())
            ),
            Light::Sky {
                zenith,
                horizon,
                ground,
                intensity,
                background,
                ..
            } => writeln!(
                out,
                "light sky zenith={} horizon={} ground={} intensity={} background={background}{shadows}",
                v3(*zenith),
                v3(*horizon),
                v3(*ground),
                num(*intensity),
            ),
        };
    }
}

/// One line for each material.
fn materials(out: &mut String, scene: &Scene) {
    for (i, m) in scene.materials.iter().enumerate() {
        let colour = |c: &Colour| match c {
            Colour::Const(c) => v3(*c),
            Colour::Field(f) => format!("field {{ {} }}", f.text()),
        };
        let pattern = match &m.pattern {
            Pattern::Solid(c) => format!("color={}", colour(c)),
            Pattern::Checker { a, b, size } => {
                format!(
                    "checker a={} b={} size={}",
                    colour(a),
                    colour(b),
                    num(*size)
                )
            }
            Pattern::Materials { a, b, size } => {
                let name = |m: &MaterialId| {
                    scene
                        .materials
                        .get(m.0 as usize)
                        .map_or("?", |m| m.name.as_str())
                };
                format!("checker a={} b={} size={}", name(a), name(b), num(*size))
            }
        };
        // A `pbr` material's own parameters, and Phong's Fresnel, only where they are given.
        let extra = match m.pbr {
            Some(p) => format!(
                " pbr roughness={} metallic={} emission={} transmission={}",
                num(p.roughness),
                num(p.metallic),
                v3(p.emission),
                num(p.transmission)
            ),
            None if m.fresnel => " fresnel".to_string(),
            None => String::new(),
        };
        let _ = writeln!(
            out,
            "material #{i} {} {pattern} ambient={} diffuse={} specular={} shininess={} reflect={} transparency={} ior={}{extra}",
            m.name, num(m.ambient), num(m.diffuse), num(m.specular), num(m.shininess), num(m.reflect),
            num(m.transparency), num(m.ior)
        );
    }
}

fn postorder(g: &Graph, id: NodeId, seen: &mut [bool], order: &mut Vec<NodeId>) {
    // Iterative, so that deep scenes cannot overflow the stack.
    let mut stack = vec![(id, false)];
    while let Some((n, expanded)) = stack.pop() {
        if seen[n.0 as usize] {
            continue;
        }
        if expanded {
            seen[n.0 as usize] = true;
            order.push(n);
        } else {
            stack.push((n, true));
            for c in g.node(n).children().into_iter().rev() {
                stack.push((c, false));
            }
        }
    }
}

/// Formats a float the shortest way that reads back exactly.
/// Formats a float for the dump: integers without a fraction, others to 10 significant
/// digits, so that round-off noise (such as 59.99999999999999 for 60°) does not show.
pub fn num(x: f64) -> String {
    if x == 0.0 || x.abs() < 1e-13 {
        return "0".to_string();
    }
    if x == x.trunc() && x.abs() < 1e15 {
        return format!("{}", x as i64);
    }
    let digits = 9 - x.abs().log10().floor() as i32;
    if !(0..=17).contains(&digits) {
        return format!("{x:e}");
    }
    let s = format!("{:.*}", digits as usize, x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

fn v2(v: [f64; 2]) -> String {
    format!("({}, {})", num(v[0]), num(v[1]))
}

fn v3(v: V3) -> String {
    format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]))
}

/// A 3×3 matrix as its rows: `[(…), (…), (…)]`.
fn m3(m: &[V3; 3]) -> String {
    format!("[{}, {}, {}]", v3(m[0]), v3(m[1]), v3(m[2]))
}

fn ids(ids: &[NodeId]) -> String {
    ids.iter()
        .map(|i| format!("%{}", i.0))
        .collect::<Vec<_>>()
        .join(", ")
}

fn node(n: &Node) -> String {
    match n {
        Node::Sphere { .. }
        | Node::Box { .. }
        | Node::RoundBox { .. }
        | Node::Plane { .. }
        | Node::Torus { .. }
        | Node::Cylinder { .. }
        | Node::Capsule { .. }
        | Node::Cone { .. }
        | Node::Ellipsoid { .. }
        | Node::Rect { .. }
        | Node::Mesh { .. }
        | Node::Bezier { .. }
        | Node::Prim { .. }
        | Node::Polygon { .. }
        | Node::Text { .. } => shape(n),
        Node::Extrude { .. }
        | Node::Revolve { .. }
        | Node::Loft { .. }
        | Node::Sweep { .. }
        | Node::Screw { .. }
        | Node::Feature { .. } => from_profiles(n),
        Node::Combine { op, children } => format!("{} {}", combine(*op), ids(children)),
        Node::SmoothCombine {
            op,
            k,
            variant,
            a,
            b,
        } => {
            let v = match variant.steps() {
                Some(n) => format!("{} steps={n}", variant.name()),
                None => variant.name().to_string(),
            };
            format!(
                "smooth_{} k={} {v} %{}, %{}",
                combine(*op),
                num(*k),
                a.0,
                b.0
            )
        }
        Node::Translate { offset, child } => format!("translate {} %{}", v3(*offset), child.0),
        Node::Rotate { matrix, child } => format!("rotate {} %{}", m3(matrix), child.0),
        Node::Scale { factor, child } => format!("scale {} %{}", num(*factor), child.0),
        Node::ScaleXyz { factors, child } => format!("scale_xyz {} %{}", v3(*factors), child.0),
        Node::Repeat {
            period,
            count,
            child,
        } => match count {
            Some(c) => format!(
                "repeat period={} count={} %{}",
                v3(*period),
                v3(*c),
                child.0
            ),
            None => format!("repeat period={} %{}", v3(*period), child.0),
        },
        Node::Mirror { axes, child } => {
            let a: String = ["x", "y", "z"]
                .iter()
                .zip(axes)
                .filter(|(_, on)| **on)
                .map(|(n, _)| *n)
                .collect();
            format!("mirror {a} %{}", child.0)
        }
        Node::RepeatPolar {
            count,
            mirror,
            child,
        } => {
            let m = if *mirror { " mirror" } else { "" };
            format!("repeat_polar count={count}{m} %{}", child.0)
        }
        Node::Wrap { radius, child } => format!("wrap {} %{}", num(*radius), child.0),
        Node::Shear { matrix, child } => format!("shear {} %{}", m3(matrix), child.0),
        Node::Taper { rate, child } => format!("taper {} %{}", num(*rate), child.0),
        Node::Morph { t, a, b } => format!("morph t={} %{}, %{}", num(*t), a.0, b.0),
        Node::Twist { rate, child } => format!("twist {} %{}", num(*rate), child.0),
        Node::Bend { rate, child } => format!("bend {} %{}", num(*rate), child.0),
        Node::Round { radius, child } => format!("round {} %{}", num(*radius), child.0),
        Node::Shell { half, child } => format!("shell half={} %{}", num(*half), child.0),
        Node::Elongate { half, child } => format!("elongate {} %{}", v3(*half), child.0),
        Node::Paint { material, child } => format!("paint #{} %{}", material.0, child.0),
        Node::Field { f, lipschitz, .. } => match lipschitz {
            Some(l) => format!("{} lipschitz={} {{ {} }}", n.kind(), num(*l), f.text()),
            None => format!("{} {{ {} }}", n.kind(), f.text()),
        },
    }
}

/// A shape's line: a primitive of the table or one of the graph's own.
fn shape(n: &Node) -> String {
    match n {
        Node::Sphere { radius } => format!("sphere radius={}", num(*radius)),
        Node::Box { half } => format!("box half={}", v3(*half)),
        Node::RoundBox { half, radius } => {
            format!("round_box half={} radius={}", v3(*half), num(*radius))
        }
        Node::Plane { normal, height } => {
            format!("plane normal={} height={}", v3(*normal), num(*height))
        }
        Node::Torus { major, minor } => {
            format!("torus major={} minor={}", num(*major), num(*minor))
        }
        Node::Cylinder {
            radius,
            half_height,
        } => {
            format!(
                "cylinder radius={} half_height={}",
                num(*radius),
                num(*half_height)
            )
        }
        Node::Capsule {
            radius,
            half_height,
        } => {
            format!(
                "capsule radius={} half_height={}",
                num(*radius),
                num(*half_height)
            )
        }
        Node::Cone {
            radius,
            half_height,
        } => format!(
            "cone radius={} half_height={}",
            num(*radius),
            num(*half_height)
        ),
        Node::Ellipsoid { radii } => format!("ellipsoid radii={}", v3(*radii)),
        Node::Rect { half } => format!("rect half={}", v2(*half)),
        Node::Mesh { mesh } => {
            let m = &mesh.0;
            format!(
                "mesh {:?} triangles={} open_edges={}",
                m.name,
                m.triangles().len(),
                m.report.open_edges
            )
        }
        Node::Bezier {
            a,
            control,
            b,
            radius,
        } => format!(
            "bezier a={} control={} b={} radius={}",
            v2(*a),
            v2(*control),
            v2(*b),
            num(*radius)
        ),
        Node::Prim { prim, args } => {
            let mut out = prim.name.to_string();
            for (i, p) in prim.params.iter().enumerate() {
                let v = match p.ty {
                    Kind::Vec2 => v2(args.v2(i)),
                    Kind::Vec3 => v3(args.v3(i)),
                    Kind::Points => {
                        let ps: Vec<String> = args.list(i).iter().map(|q| v3(*q)).collect();
                        format!("[{}]", ps.join(" "))
                    }
                    Kind::Float | Kind::Int | Kind::Angle => num(args.f(i)),
                };
                out += &format!(" {}={v}", p.name);
            }
            out
        }
        Node::Polygon { points } => {
            let ps: Vec<String> = points.iter().map(|q| v2(*q)).collect();
            format!("polygon {}", ps.join(" "))
        }
        Node::Text {
            text,
            size,
            font,
            outline,
        } => format!(
            "text {text:?} size={} font={font:?} glyphs={} segments={}",
            num(*size),
            outline.glyphs().len(),
            outline.segments()
        ),
        _ => unreachable!("{} is not a shape", n.kind()),
    }
}

/// The line of a shape made from profiles or other shapes: an extrusion, revolution, loft,
/// sweep or screw, or a feature between two shapes.
fn from_profiles(n: &Node) -> String {
    match n {
        Node::Extrude {
            half_height,
            round,
            child,
        } => format!(
            "extrude half_height={} round={} %{}",
            num(*half_height),
            num(*round),
            child.0
        ),
        Node::Revolve { offset, child } => {
            format!("revolve offset={} %{}", num(*offset), child.0)
        }
        Node::Loft {
            half_height,
            spread,
            bottom,
            top,
        } => format!(
            "loft half_height={} spread={} %{}, %{}",
            num(*half_height),
            num(*spread),
            bottom.0,
            top.0
        ),
        Node::Sweep {
            path,
            inner,
            extent,
            folds,
            child,
        } => format!(
            "sweep {} inner={} extent={}{} %{}",
            path.0.describe(),
            num(*inner),
            num(*extent),
            if *folds { " folds" } else { "" },
            child.0
        ),
        Node::Screw {
            pitch,
            half_height,
            inner,
            floor,
            child,
        } => format!(
            "screw pitch={} half_height={} inner={} floor={} %{}",
            num(*pitch),
            num(*half_height),
            num(*inner),
            num(*floor),
            child.0
        ),
        Node::Feature { op, a, b } => {
            let size = match *op {
                Feature::Engrave { depth } => format!("depth={}", num(depth)),
                Feature::Groove { width, depth } => {
                    format!("width={} depth={}", num(width), num(depth))
                }
                Feature::Tongue { width, height } => {
                    format!("width={} height={}", num(width), num(height))
                }
                Feature::Pipe { radius } => format!("radius={}", num(radius)),
            };
            format!("{} {size} %{}, %{}", op.name(), a.0, b.0)
        }
        _ => unreachable!("{} is not made from profiles", n.kind()),
    }
}

fn combine(op: Combine) -> &'static str {
    match op {
        Combine::Union => "union",
        Combine::Intersect => "intersect",
        Combine::Subtract => "subtract",
    }
}
