//! The session's loads: the time from an edit, a file saved in place, reloads that keep the
//! moved camera and errors that keep the image, a changed mesh file, and every load held to the
//! memory limit.

use super::*;

#[test]
fn edit_to_pixel_counts_from_the_edit() {
    // A file renamed back keeps its old modification time: the edit is when the watcher
    // saw it. A file written after the event counts from its writing.
    let old = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000);
    let seen = old + Duration::from_secs(3600);
    assert_eq!(edit_time(Some(old), Some(seen)), Some(seen));
    let written = seen + Duration::from_millis(5);
    assert_eq!(edit_time(Some(written), Some(seen)), Some(written));
    assert_eq!(edit_time(Some(old), None), Some(old));
    assert_eq!(edit_time(None, Some(seen)), Some(seen));
}

#[test]
fn a_file_saved_in_place_is_read_once_written() {
    // An editor saving in place truncates the file, then writes it: a load that runs in
    // between waits for the contents instead of reporting an empty scene; a file that
    // stays empty is loaded as it is (and fails: no `scene` block).
    let (dir, file) = temp_file("in-place", "a.sdf");
    std::fs::write(&file, "").unwrap();
    let writer = {
        let file = file.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            std::fs::write(file, SCENE).unwrap();
        })
    };
    let mut s = Session::new(file.clone(), Options::default(), Device::Cpu);
    assert!(s.load().ok, "the load waited for the file's contents");
    writer.join().unwrap();
    std::fs::write(&file, "").unwrap();
    let started = Instant::now();
    let outcome = s.load();
    assert!(
        !outcome.ok && outcome.summary.contains("E0503"),
        "{}",
        outcome.summary
    );
    assert!(started.elapsed() >= EMPTY_PATIENCE);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reloads_keep_the_moved_camera_and_errors_keep_the_image() {
    let (dir, file) = temp_file("session", "s.sdf");
    std::fs::write(&file, SCENE).unwrap();
    let mut s = loaded(file.clone(), Options::default(), Device::Cpu);
    // aa 2: four jittered samples, then nothing more to render.
    assert_eq!(settle(&mut s), 4);
    assert!(s.settled());
    let first = s.image().unwrap();

    // The file's camera moves the view until the user moves it.
    std::fs::write(&file, SCENE.replace("(0, 1, -4)", "(0, 1.2, -4)")).unwrap();
    assert!(s.needs_reload(&[]));
    assert!(s.load().ok);
    assert!(!s.needs_reload(&[]), "nothing changed since");
    assert_eq!(s.camera().unwrap().position, [0.0, 1.2, -4.0]);
    s.rotate(30.0, 0.0);
    let moved = s.camera().unwrap();
    settle(&mut s);

    // A clean reload keeps the user's camera; R returns to the file's.
    std::fs::write(&file, SCENE.replace("sphere(0.5)", "sphere(0.6)")).unwrap();
    let outcome = s.load();
    assert!(outcome.ok && outcome.number == 2);
    assert_eq!(s.camera().unwrap(), moved);
    settle(&mut s);
    let good = s.image().unwrap();
    assert_ne!(good, first);

    // An edit with errors keeps the image and says why in the title.
    std::fs::write(&file, SCENE.replace("sphere(0.5)", "sphre(0.5)")).unwrap();
    let outcome = s.load();
    assert!(!outcome.ok);
    assert!(outcome.summary.contains("E0201"), "{}", outcome.summary);
    assert!(s.title(false).contains("E0201"));
    assert!(s.settled());
    assert_eq!(s.image(), Some(good.clone()));

    // So does a file that disappears; a failed load retries on any scene file's change.
    std::fs::remove_file(&file).unwrap();
    assert!(s.needs_reload(&[]));
    assert!(!s.load().ok);
    assert_eq!(s.image(), Some(good.clone()));
    assert!(s.needs_reload(&[dir.join("other.sdf")]));
    assert!(
        !s.needs_reload(std::slice::from_ref(&file)),
        "its contents are those it failed on"
    );
    s.reset_camera();
    assert!(!s.camera_moved());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An ASCII STL of the tetrahedron with corners at the origin and at `size` along each axis.
fn tetrahedron_stl(size: f64) -> String {
    let [o, x, y, z] = [
        [0.0; 3],
        [size, 0.0, 0.0],
        [0.0, size, 0.0],
        [0.0, 0.0, size],
    ];
    let mut stl = String::from("solid t\n");
    for f in [[o, y, x], [o, x, z], [o, z, y], [x, y, z]] {
        stl.push_str(" facet normal 0 0 0\n  outer loop\n");
        for v in f {
            stl.push_str(&format!("   vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        stl.push_str("  endloop\n endfacet\n");
    }
    stl + "endsolid t\n"
}

/// The files a scene reads besides its sources (a mesh) are watched as its imports are: a
/// change of the mesh file calls for a reload, and the reload shows the new mesh.
#[test]
fn a_changed_mesh_file_reloads() {
    let dir = temp_dir("session-mesh");
    let (file, mesh) = (dir.join("s.sdf"), dir.join("part.stl"));
    std::fs::write(&mesh, tetrahedron_stl(1.0)).unwrap();
    std::fs::write(
        &file,
        SCENE.replace(
            "sphere(0.5).translate(0, 0.5, 0)",
            "mesh(\"part.stl\").translate(-0.3, 0, 0)",
        ),
    )
    .unwrap();
    let mut s = loaded(file.clone(), Options::default(), Device::Cpu);
    assert!(
        s.files().iter().any(|f| f.ends_with("part.stl")),
        "{:?}",
        s.files()
    );
    assert!(!s.needs_reload(&[]));
    settle(&mut s);
    let before = s.image().unwrap();
    std::fs::write(&mesh, tetrahedron_stl(1.4)).unwrap();
    assert!(s.needs_reload(std::slice::from_ref(&mesh)));
    assert!(s.load().ok);
    assert!(!s.needs_reload(&[]), "nothing changed since");
    settle(&mut s);
    assert_ne!(s.image().unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every load, the first and those after it (prepared as the scene before was), is held to the
/// `memory` limit at the view's size, whatever size the scene's settings state: a scene that
/// asks for a picture far above the limit is shown in a small view, and an edit loaded while
/// the view is larger than the limit allows is refused with the limit's message, the image
/// before staying on show.
#[test]
fn every_load_is_held_to_the_memory_limit_at_the_views_size() {
    let (dir, file) = temp_file("session-memory", "m.sdf");
    // 8000x6000 pixels: a render of the scene's size is far above 32 MiB.
    let huge = SCENE.replace("width: 32, height: 24", "width: 8000, height: 6000");
    std::fs::write(&file, &huge).unwrap();
    let mut job = Job::default();
    job.limits.apply("memory=32").unwrap();
    let options = Options {
        job,
        ..Options::default()
    };
    let mut s = Session::new(file.clone(), options, Device::Cpu);
    s.set_size(32, 24);
    let first = s.load();
    assert!(first.ok, "{}", first.summary);
    settle(&mut s);
    let shown = s.image().expect("an image");

    // A later load, in a view above the limit: refused, saying which limit.
    s.set_size(4000, 3000);
    std::fs::write(&file, huge.replace("sphere(0.5)", "sphere(0.6)")).unwrap();
    let refused = s.load();
    assert!(!refused.ok);
    assert!(
        refused
            .summary
            .contains("more than the memory limit of 32 MiB; raise it with `--limit memory="),
        "{}",
        refused.summary
    );
    assert!(
        s.title(false).contains("memory limit"),
        "{}",
        s.title(false)
    );
    assert_eq!(s.image(), Some(shown));

    // The same edit in a small view again loads.
    s.set_size(32, 24);
    let again = s.load();
    assert!(again.ok, "{}", again.summary);
    let _ = std::fs::remove_dir_all(&dir);
}
