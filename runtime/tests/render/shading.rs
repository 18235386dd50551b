//! Secondary rays and lights in CPU renders: shadows and their penumbra, mirrors, clear and
//! sunk glass, light falloff, and the glass blob's explained artefacts of issue 24, item 4.

use crate::common;
use crate::render::{
    luminance, mirror_scene, project, render, render_as, seen_from, shadow_scene, METHODS,
};
use common::*;
use sdfc_compiler::{Light, Node, Pattern, Scene};

#[test]
fn a_shadowed_pixel_is_darker_than_its_lit_neighbour() {
    for method in METHODS {
        for penumbra in [0.0, (1.0f64 / 8.0).atan()] {
            let scene = shadow_scene(penumbra);
            let r = render_as(method, &scene);
            // The shadow's centre on the floor, on the line from the light through the sphere.
            let (sx, sy) = project(&scene, [-0.5, 0.0, 0.0]);
            let (lx, ly) = project(&scene, [-0.5, 0.0, -1.2]);
            let (dark, lit) = (
                luminance(r.image.pixel(sx, sy)),
                luminance(r.image.pixel(lx, ly)),
            );
            assert!(
                dark < 0.5 * lit,
                "penumbra {penumbra}: shadow {dark}, lit {lit}"
            );
            // Hard shadows leave only the ambient term: k_a · C.
            if penumbra == 0.0 {
                assert!(
                    (r.image.pixel(sx, sy)[0] - 0.1 * 0.8).abs() < 1e-4,
                    "{:?}",
                    r.image.pixel(sx, sy)
                );
            }
        }
    }
}

/// A red ball above a floor whose reflectivity is `reflect`.
/// A glass ball half sunk into a checkered floor shows the floor through it (refracted rays
/// inside the glass find the floor's surface there), not a dull dome of background colour:
/// within the ball's lower half, both checker colours are seen.
#[test]
fn glass_sunk_into_the_floor_shows_the_floor_through_it() {
    let text = "material glass = phong { color: (1, 1, 1), transparency: 0.9, ior: 1.5 };\n\
                material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 0.5 };\n\
                camera { position: (0, 1.5, -3), look_at: (0, 0.2, 0), fov: 50deg }\n\
                light point { position: (2, 5, -3) }\n\
                render { width: 320, height: 240 }\n\
                scene { plane((0, 1, 0), 0) @ floor; sphere(0.8) @ glass; }";
    let (scene, diags, _) = sdfc_compiler::check_str("glass.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let r = render(&scene);
    // The pixels of the ball's lower half, above the floor's horizon line behind it.
    let (mut bright, mut dark, mut all) = (0, 0, 0);
    for y in 110..150 {
        for x in 130..190 {
            let l = luminance(r.image.pixel(x, y));
            bright += (l > 0.4) as u32;
            dark += (l < 0.2) as u32;
            all += 1;
        }
    }
    assert!(
        bright * 8 > all && dark * 8 > all,
        "{bright} bright and {dark} dark of {all} pixels: the floor is not seen through the glass"
    );
}

/// `penumbra` means what its name says: the wider it is, the more of the floor around the
/// shadow lies in a partial shadow, and the further the image is from the hard shadow's.
#[test]
fn a_wider_penumbra_gives_a_softer_shadow() {
    let hard = render(&shadow_scene(0.0));
    let apart = |deg: f64| {
        let r = render(&shadow_scene(deg.to_radians()));
        let partial = r
            .image
            .linear
            .iter()
            .zip(&hard.image.linear)
            .filter(|(a, b)| (luminance(**a) - luminance(**b)).abs() > 0.01)
            .count();
        partial
    };
    let (narrow, medium, wide) = (apart(1.0), apart(5.0), apart(20.0));
    assert!(
        narrow < medium && medium < wide && narrow > 0,
        "pixels off the hard shadow: 1° {narrow}, 5° {medium}, 20° {wide}"
    );
}

#[test]
fn a_mirror_shows_the_reflected_object() {
    for method in METHODS {
        // Where the camera sees the ball's mirror image (its centre reflected in y = 0).
        let with = render_as(method, &mirror_scene(0.9));
        let without = render_as(method, &mirror_scene(0.0));
        let (x, y) = project(&mirror_scene(0.9), [0.0, -0.6, 2.0]);
        let (m, plain) = (with.image.pixel(x, y), without.image.pixel(x, y));
        assert!(m[0] > 2.0 * m[1] + 0.05, "mirror pixel not red: {m:?}");
        assert!(
            (plain[0] - plain[1]).abs() < 1e-4,
            "plain floor pixel not grey: {plain:?}"
        );
        assert!(
            with.stats.counters.secondary_rays > 0 && without.stats.counters.secondary_rays == 0
        );
    }
}

/// A checkerboard wall behind where a ball may stand.
fn glass_scene(ball: Option<(f64, f64)>) -> Scene {
    let mut b = Build::new();
    let wall = b.add(Node::Plane {
        normal: [0.0, 0.0, -1.0],
        height: -3.0,
    });
    let mut root = wall;
    if let Some((transparency, ior)) = ball {
        let glass = b.material([1.0, 1.0, 1.0], 0.0, transparency);
        b.scene.materials[glass.0 as usize].ior = ior;
        b.scene.materials[glass.0 as usize].specular = 0.0;
        let s = b.add(Node::Sphere { radius: 1.0 });
        let s = b.paint(s, glass);
        root = b.add(Node::Combine {
            op: sdfc_compiler::Combine::Union,
            children: vec![wall, s],
        });
    }
    b.scene.materials[0].pattern = Pattern::Checker {
        a: [0.9, 0.9, 0.9].into(),
        b: [0.1, 0.1, 0.1].into(),
        size: 0.5,
    };
    b.point_light([0.0, 0.0, -6.0], 4.0);
    let mut scene = b.finish(root);
    seen_from(&mut scene, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), (96, 72));
    scene
}

/// How many pixels of `a` and `b` differ by more than 0.02 in red.
fn red_differs(a: &sdfc_runtime::image::Image, b: &sdfc_runtime::image::Image) -> usize {
    a.linear
        .iter()
        .zip(&b.linear)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 0.02)
        .count()
}

#[test]
fn clear_glass_of_index_one_is_invisible() {
    for method in METHODS {
        let bare = render_as(method, &glass_scene(None));
        let clear = render_as(method, &glass_scene(Some((1.0, 1.0))));
        let differ = red_differs(&bare.image, &clear.image);
        assert!(
            differ * 50 < bare.image.linear.len(),
            "{differ} pixels differ"
        );
        assert!(clear.stats.counters.secondary_rays > 0);
        // Real glass bends the checkerboard: many pixels change, none is NaN.
        let glass = render_as(method, &glass_scene(Some((0.9, 1.5))));
        let changed = red_differs(&bare.image, &glass.image);
        assert!(changed > 300, "{changed}");
        assert!(glass
            .image
            .linear
            .iter()
            .all(|c| c.iter().all(|v| v.is_finite())));
    }
}

#[test]
fn a_point_light_does_not_reach_past_its_radius() {
    for method in METHODS {
        let mut scene = shadow_scene(0.0);
        if let Some(Light::Point { radius, .. }) = scene.lights.first_mut() {
            *radius = 2.0;
        }
        let r = render_as(method, &scene);
        let (x, y) = project(&scene, [1.5, 0.0, -1.5]);
        assert!(
            (r.image.pixel(x, y)[0] - 0.08).abs() < 1e-5,
            "{:?}",
            r.image.pixel(x, y)
        );
    }
}

fn checked(name: &str, text: &str) -> Scene {
    let (scene, diags, _) = sdfc_compiler::check_str(name, text);
    scene.unwrap_or_else(|| panic!("{diags:?}"))
}

/// Issue 24, item 4 (docs/rendering.md, "Secondary rays"): in a glass `smooth_union` blob,
/// the dark crescents are rays that total internal reflection keeps inside the glass until
/// `max_depth`, and the speckled band is the distant checkerboard seen through the glass.
/// On a plain floor, raising `max_depth` from 5 to 30 removes nearly all the dark pixels,
/// and the band is smooth.
#[test]
fn the_glass_blobs_crescents_are_max_depth_and_its_band_the_checker() {
    let blob = "material glass = phong { color: (1, 1, 1), transparency: 0.9, ior: 1.5 };\n\
                material floor = phong { color: (0.5, 0.5, 0.5) };\n\
                camera { position: (0, 2, -6), look_at: (0, 0.8, 0), fov: 35deg }\n\
                light point { position: (4, 6, -4), intensity: 1, radius: 30 }\n\
                render { width: 480, height: 360 }\n\
                scene {\n\
                  plane((0, 1, 0), -0.5) @ floor;\n\
                  smooth_union(0.4, sphere(0.8).translate(0, 1, 0), torus(1.0, 0.3).rotate_x(90deg)) @ glass;\n\
                }";
    let dark = |depth: u32| {
        let mut scene = checked("blob.sdf", blob);
        scene.settings.max_depth = depth;
        let g = grey(&render(&scene).image);
        let band = roughness(&g, 480, (180, 158, 300, 176));
        (g.iter().filter(|&&l| l < 0.15).count(), band)
    };
    let ((shallow, band), (deep, _)) = (dark(5), dark(30));
    println!("dark pixels: {shallow} at max_depth 5, {deep} at 30; band roughness {band:.5}");
    assert!(shallow > 500, "{shallow} dark pixels at max_depth 5");
    assert!(deep * 20 < shallow, "{deep} dark pixels at max_depth 30");
    assert!(
        band < 0.003,
        "the band through the glass is rough: {band:.5}"
    );
}
