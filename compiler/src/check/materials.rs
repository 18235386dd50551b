//! The `material` items: a material of each kind (`phong`, `checker`, `pbr`) from its fields,
//! the ids every material gets before any item is evaluated, and a checker of two materials
//! (`checker { a: gold, b: rubber }`), whose pair is checked once every material is known.

use super::eval::{self, Ctx};
use super::types::Value;
use super::{builtins, dup, field_span, unknown_kind};
use crate::diagnostics::Diagnostic;
use crate::scene::{Colour, Material, MaterialId, Pattern, Pbr, Scene};
use crate::span::Span;
use crate::syntax::ast;
use std::collections::HashMap;

pub(super) fn material(
    cx: &mut Ctx,
    scene: &mut Scene,
    name: &ast::Ident,
    kind: &ast::Ident,
    fields: &[ast::Field],
) {
    let rec = builtins::MATERIALS.iter().find(|r| r.name == kind.name);
    let Some(&(id, first)) = cx.material_ids.get(&name.name) else {
        return;
    };
    if first != name.span {
        // A second definition, reported by `declare_materials`.
        return;
    }
    let Some(rec) = rec else {
        let note = "the material kinds are phong, checker and pbr";
        return unknown_kind(cx, "material", kind, builtins::MATERIALS, note);
    };
    if rec.name == "checker" && pair(cx, scene, id, name, kind, fields) {
        return;
    }
    let f = eval::record(cx, rec, fields, kind);
    // A colour field's value, or the constant's.
    let colour = |v: &Value| match v {
        Value::Colour(field) => Colour::Field((**field).clone()),
        other => Colour::Const(other.v3()),
    };
    if rec.name == "pbr" {
        scene.materials[id.0 as usize] = pbr_material(&name.name, &f, colour(&f["base_color"]));
        return;
    }
    let (reflect, transparency) = (f["reflect"].num(), f["transparency"].num());
    if reflect + transparency > 1.0 + 1e-12 {
        cx.error(
            Diagnostic::error(
                "E0506",
                "`reflect` and `transparency` add up to more than 1",
                name.span,
            )
            .with_label(format!(
                "{reflect} + {transparency} = {}",
                reflect + transparency
            ))
            .with_note("the surface's own colour is weighted by 1 − reflect − transparency"),
        );
    }
    let pattern = if rec.name == "checker" {
        Pattern::Checker {
            a: colour(&f["a"]),
            b: colour(&f["b"]),
            size: f["size"].num(),
        }
    } else {
        Pattern::Solid(colour(&f["color"]))
    };
    scene.materials[id.0 as usize] = Material {
        name: name.name.clone(),
        pattern,
        ambient: f["ambient"].num(),
        diffuse: f["diffuse"].num(),
        specular: f["specular"].num(),
        shininess: f["shininess"].num(),
        reflect,
        transparency,
        ior: f["ior"].num(),
        fresnel: matches!(f["fresnel"], Value::Bool(true)),
        pbr: None,
        frame: Vec::new(),
    };
}

/// A `pbr` material of base colour `base` from its record's values: its transmission is the
/// transparency of its dielectric part, `transmission·(1 − metallic)`, and its Phong fields
/// the nearest Phong material's (no ambient term, the diffuse weight of the dielectric part,
/// the reflectance at normal incidence as `specular`, the exponent of the same highlight
/// width), which the material tables of `--part map` and the Shadertoy page show.
fn pbr_material(name: &str, f: &HashMap<&'static str, Value>, base: Colour) -> Material {
    let p = Pbr {
        roughness: f["roughness"].num(),
        metallic: f["metallic"].num(),
        emission: f["emission"].v3(),
        transmission: f["transmission"].num(),
    };
    let ior = f["ior"].num();
    let transparency = p.transmission * (1.0 - p.metallic);
    let grey = base
        .constant()
        .map_or(Material::COLOR[0], |c| (c[0] + c[1] + c[2]) / 3.0);
    Material {
        name: name.to_string(),
        pattern: Pattern::Solid(base),
        ambient: 0.0,
        diffuse: 1.0 - p.metallic - transparency,
        specular: crate::scene::pbr::f0(ior) * (1.0 - p.metallic) + grey * p.metallic,
        shininess: p.shininess(),
        reflect: 0.0,
        transparency,
        ior,
        fresnel: true,
        pbr: Some(p),
        frame: Vec::new(),
    }
}

/// Gives every material its id before any item is evaluated, so that `@ name` finds a
/// material declared anywhere in the program, above or below its use; a second definition
/// of a name is E0207. Each material's fields are evaluated later, in source order.
pub(super) fn declare_materials(cx: &mut Ctx, scene: &mut Scene, items: &[ast::Item]) {
    for item in items {
        let ast::Item::Material { name, .. } = item else {
            continue;
        };
        if let Some(&(_, first)) = cx.material_ids.get(&name.name) {
            dup(cx, "the material", name, first);
            continue;
        }
        let id = MaterialId(scene.materials.len() as u32);
        scene.materials.push(Material {
            name: name.name.clone(),
            ..Material::default_material()
        });
        cx.material_ids.insert(name.name.clone(), (id, name.span));
    }
}

/// The material a checker's field `a` or `b` names (a bare name of a material that no
/// constant hides), with the span of the field's value; `None` where the field is not given.
fn named(cx: &Ctx, fields: &[ast::Field], field: &str) -> Option<(Option<MaterialId>, Span)> {
    let f = fields.iter().find(|f| f.name.name == field)?;
    let m = match &f.value.kind {
        ast::ExprKind::Var(v) if !cx.declared.contains_key(&v.name) => {
            cx.material_ids.get(&v.name).map(|m| m.0)
        }
        _ => None,
    };
    Some((m, f.value.span))
}

/// A checker whose `a` or `b` names a material: with both, the checker of the two materials
/// (its `size` evaluated; any other field is E0400, the cells taking every property from
/// their materials); with one, E0300 at the other. Returns whether it was such a checker.
fn pair(
    cx: &mut Ctx,
    scene: &mut Scene,
    id: MaterialId,
    name: &ast::Ident,
    kind: &ast::Ident,
    fields: &[ast::Field],
) -> bool {
    let (a, b) = (named(cx, fields, "a"), named(cx, fields, "b"));
    let (a, b) = match (a, b) {
        (Some((Some(a), _)), Some((Some(b), _))) => (a, b),
        (Some((Some(_), _)), other) | (other, Some((Some(_), _))) => {
            let (field, colour) = if matches!(named(cx, fields, "a"), Some((Some(_), _))) {
                ("b", "a")
            } else {
                ("a", "b")
            };
            let at = other.map_or(kind.span, |(_, span)| span);
            cx.error(
                Diagnostic::error(
                    "E0300",
                    format!("`{field}` of this checker is not a material, but its `{colour}` is"),
                    at,
                )
                .with_label(if other.is_some() {
                    "a colour, not a material"
                } else {
                    "missing: the default is a colour"
                })
                .with_help(format!(
                    "a checker pairs two colours or two materials: give `{field}` a material's name"
                )),
            );
            return true;
        }
        _ => return false,
    };
    for f in fields {
        if !matches!(f.name.name.as_str(), "a" | "b" | "size") {
            cx.error(
                Diagnostic::error(
                    "E0400",
                    format!("`{}` has no use in a checker of two materials", f.name.name),
                    f.name.span,
                )
                .with_label("each cell takes every property from its material")
                .with_help("set it on the materials `a` and `b` instead"),
            );
        }
    }
    let size: Vec<ast::Field> = fields
        .iter()
        .filter(|f| f.name.name == "size")
        .cloned()
        .collect();
    let f = eval::record(cx, &builtins::MATERIALS[1], &size, kind);
    scene.materials[id.0 as usize] = Material {
        name: name.name.clone(),
        pattern: Pattern::Materials {
            a,
            b,
            size: f["size"].num(),
        },
        ..Material::default_material()
    };
    true
}

/// Checks the pairs of the checkers of two materials, once every material is known (a
/// material may be declared below its use): E0400 where either is such a checker itself
/// (itself included), is transparent, or where one is `pbr` and the other Phong.
pub(super) fn check_pairs(cx: &mut Ctx, scene: &Scene, items: &[ast::Item]) {
    for item in items {
        let ast::Item::Material { name, fields, .. } = item else {
            continue;
        };
        let Some(&(id, first)) = cx.material_ids.get(&name.name) else {
            continue;
        };
        let Some(Pattern::Materials { a, b, .. }) =
            scene.materials.get(id.0 as usize).map(|m| &m.pattern)
        else {
            continue;
        };
        if first != name.span {
            continue;
        }
        let at = |field: &str| field_span(fields, field).unwrap_or(name.span);
        let (ma, mb) = (
            &scene.materials[a.0 as usize],
            &scene.materials[b.0 as usize],
        );
        let refuse = |cx: &mut Ctx, field: &str, message: String, note: &str| {
            cx.error(
                Diagnostic::error("E0400", message, at(field))
                    .with_label(format!("the checker's `{field}`"))
                    .with_note(note.to_string()),
            );
        };
        for (field, m) in [("a", ma), ("b", mb)] {
            if matches!(m.pattern, Pattern::Materials { .. }) {
                refuse(
                    cx,
                    field,
                    format!("`{}` is itself a checker of two materials", m.name),
                    "a checker's materials are phong, pbr or a checker of two colours",
                );
            } else if m.transparency > 0.0 {
                refuse(
                    cx,
                    field,
                    format!("`{}` is transparent", m.name),
                    "a checker's materials are opaque: glass and shadow rays find a material by its point, not by the cells a pixel sees",
                );
            }
        }
        let nested = [ma, mb]
            .iter()
            .any(|m| matches!(m.pattern, Pattern::Materials { .. }));
        if !nested && ma.pbr.is_some() != mb.pbr.is_some() {
            let kind = |m: &Material| if m.pbr.is_some() { "pbr" } else { "phong" };
            refuse(
                cx,
                "b",
                format!(
                    "`{}` is {} but `{}` is {}",
                    ma.name,
                    kind(ma),
                    mb.name,
                    kind(mb)
                ),
                "a checker's two materials are of one model: where a pixel sees both, their parameters are blended",
            );
        }
    }
}
