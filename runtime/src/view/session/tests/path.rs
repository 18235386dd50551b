//! The viewer session's tests of path-traced scenes: samples accumulated one a frame, in
//! linear light, and their mean graded as `sdfc render` grades it (on the CPU, and on wgpu
//! through lavapipe where no GPU is there).

use super::*;
use sdfc_compiler::Tonemap;

/// The scene path traced with `look` added to its render settings (a tone curve, an exposure).
fn path_scene(look: &str) -> String {
    let look = match look {
        "" => String::new(),
        l => format!(", {l}"),
    };
    SCENE.replace(
        "aa: 2 }",
        &format!("method: \"path\", samples: 4, bounces: 2{look} }}"),
    )
}

/// The curves a path-traced scene is shown under: the default (filmic), Reinhard's with an
/// exposure, and none.
const LOOKS: [(&str, Tonemap); 3] = [
    ("", Tonemap::Filmic),
    ("tonemap: \"reinhard\", exposure: 1.5", Tonemap::Reinhard),
    ("tonemap: \"none\"", Tonemap::None),
];

/// `sdfc render`'s picture of the session's scene, graded as the scene says, from the
/// camera on show: its `samples` from the first (`one`: sample `one` alone, ungraded). On
/// wgpu, whose kernel the viewer specialised ungraded, the linear render is graded by the
/// formula (`look::grade`).
fn direct(s: &Session, samples: u32, one: Option<u32>) -> Image {
    let good = s.good.as_ref().unwrap();
    let mut scene = good.scene.clone();
    let (w, h) = (scene.settings.width, scene.settings.height);
    scene.camera = camera::jittered(&s.camera().unwrap(), 0.0, 0.0, w, h);
    (scene.settings.samples, scene.settings.first_sample) = (samples, 0);
    let g = good.grade;
    let on_cpu = good.prepared.as_wgpu().is_none();
    match one {
        Some(k) => (scene.settings.samples, scene.settings.first_sample) = (1, k),
        None if on_cpu => {
            (scene.settings.exposure, scene.settings.tonemap) = (g.exposure, g.tonemap)
        }
        None => {}
    }
    let mut image = good
        .prepared
        .render(&scene, &|_| {})
        .expect("a render")
        .render
        .image;
    if one.is_none() && !on_cpu {
        for c in &mut image.linear {
            *c = c.map(|x| sdfc_compiler::look::grade(g.tonemap, g.exposure, x as f64) as f32);
        }
    }
    image
}

/// The largest difference of two images' channels.
fn most(a: &Image, b: &Image) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.linear
        .iter()
        .zip(&b.linear)
        .flat_map(|(a, b)| (0..3).map(move |i| (a[i] - b[i]).abs()))
        .fold(0.0f32, f32::max)
}

/// The mean of the samples graded each on its own (what the viewer showed when it added up
/// graded frames): another picture than the graded mean under a curve.
fn mean_of_graded(s: &Session, samples: u32) -> Image {
    let grade = s.good.as_ref().unwrap().grade;
    let frames: Vec<Image> = (0..samples).map(|k| direct(s, samples, Some(k))).collect();
    let mut mean = frames[0].clone();
    for (i, c) in mean.linear.iter_mut().enumerate() {
        *c = [0.0; 3];
        for f in &frames {
            let g = grade.apply(f.linear[i]);
            *c = std::array::from_fn(|ch| c[ch] + g[ch]);
        }
        *c = c.map(|x| x / samples as f32);
    }
    mean
}

/// A path-traced scene accumulates one sample a frame, the next of its random stream, while
/// the camera rests, up to its `samples`, saying in the title how many it has; the picture is
/// then the path tracer's of that many samples, graded as `sdfc render` grades it under every
/// tone curve (the frames add up in linear light: a mean of graded frames differs); any
/// change starts again.
#[test]
fn a_path_traced_picture_accumulates_its_samples_while_the_camera_rests() {
    let (dir, file) = temp_file("path-view", "s.sdf");
    for (look, curve) in LOOKS {
        std::fs::write(&file, path_scene(look)).unwrap();
        let mut s = loaded(file.clone(), Options::default(), Device::Cpu);
        assert_eq!(s.good.as_ref().unwrap().grade.tonemap, curve, "{look}");
        let info = s.frame().expect("a frame").expect("a frame");
        assert_eq!((info.samples, info.target), (1, 4));
        assert_title_ends(&s, " | 1/4 samples");
        assert_eq!(settle(&mut s), 3);
        assert_title_ends(&s, " | 4/4 samples");
        let shown = s.image().expect("the image");
        let render = direct(&s, 4, None);
        let apart = most(&shown, &render);
        assert!(
            apart < 1e-5,
            "{look}: the frames add up to the 4-sample picture: {apart}"
        );
        // Under a curve the mean of graded frames is another picture.
        let graded = most(&mean_of_graded(&s, 4), &render);
        assert!(
            (curve == Tonemap::None) == (graded < 1e-5),
            "{look}: graded frames' mean {graded} apart"
        );
        // A frame of one sample differs from it (the frames were not the same sample).
        assert_ne!(direct(&s, 4, Some(3)).linear, render.linear);
        // Moving the camera starts again.
        s.rotate(20.0, 0.0);
        let info = s.frame().expect("a frame").expect("a frame while moving");
        assert_eq!(info.samples, 1);
        settle(&mut s);
        assert_title_ends(&s, " | 4/4 samples");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// On wgpu the samples add up on the device in linear light and the accumulating pass grades
/// their mean: the image read back is the kernel's render of the scene's samples, graded, to
/// the rounding of summing frames, under the default filmic curve and Reinhard's with an
/// exposure; the title says how many samples it has.
#[test]
fn on_the_device_a_path_traced_picture_is_graded_from_its_linear_mean() {
    let Some(gpu) = wgpu() else { return };
    let (dir, file) = temp_file("path-resident", "s.sdf");
    let options = specialised();
    for (look, curve) in &LOOKS[..2] {
        std::fs::write(&file, path_scene(look)).unwrap();
        let mut s = loaded(file.clone(), options.clone(), Device::Wgpu(gpu.clone()));
        settle_all(&mut s);
        assert_eq!(s.good.as_ref().unwrap().grade.tonemap, *curve);
        assert!(s.host_image().is_none(), "no frame crossed to the host");
        assert_title_ends(&s, " | 4/4 samples");
        let shown = s.image().expect("the image, read back");
        let render = direct(&s, 4, None);
        let apart = most(&shown, &render);
        assert!(apart < 1e-4, "{look}: the device's mean, graded: {apart}");
        let graded = most(&mean_of_graded(&s, 4), &render);
        assert!(graded > 1e-3, "{look}: graded frames' mean {graded} apart");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
