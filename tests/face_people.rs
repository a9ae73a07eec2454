//! One face per person: `face_fit` on a folder of four people's photos gives four people, each
//! fitted as well as when fitted alone, where fitting all the photos as one face (the old
//! rule, `group: "folder"`) mixes them.
//!
//! No photo set with landmarks of several people is in the shared data, so the people are
//! made here: four known faces (the generic MediaPipe mesh under four different smooth
//! identity changes, written out below), each seen by three cameras (640×480, f = 1000 px,
//! 0.5 m away, yaw 0 and ±35°); their 68 landmarks are the projections of the known faces'
//! landmark vertices (jaw points on each view's silhouette) with 0.5 px of seeded noise, in
//! `.pts` files. The photos are plain grey pictures of the right size (the fit only reads
//! landmarks from them); Bob's are PPM. Two people are laid out by the name rule
//! (`alice_front.png`, …), two in subfolders (`carol/front.png`, …).
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};
use std::process::Command;

use emilion::face::adapt::AdaptOptions;
use emilion::face::contour::silhouette;
use emilion::face::fit_people::fit_people;
use emilion::face::landmarks::landmark_positions;
use emilion::face::people::{group_people, Grouping};
use emilion::face::FaceMesh;
use emilion::geometry::{Camera, SplitMix64, Vec3};
use nalgebra::Matrix3;

fn temp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("face_people")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn gauss(d2: f64, s: f64) -> f64 {
    (-d2 / (2.0 * s * s)).exp()
}

/// A known person: face `width` and lower-face `length` factors, nose tip `nose` m further
/// out, eyes `eyes` m further apart each.
fn person(g: &FaceMesh, width: f64, length: f64, nose: f64, eyes: f64) -> FaceMesh {
    let lm = landmark_positions(g);
    let tip = g.positions[4];
    let eye = |r: std::ops::Range<usize>| lm[r.clone()].iter().sum::<Vec3>() / r.len() as f64;
    let (right, left) = (eye(36..42), eye(42..48));
    let nose_base_y = g.positions[2].y;
    let mut out = g.clone();
    for (q, o) in out.positions.iter_mut().zip(&g.positions) {
        let mut d = Vec3::zeros();
        d.x += (width - 1.0) * o.x;
        d.y -= (length - 1.0) * (nose_base_y - o.y).max(0.0);
        d.z += nose * gauss((o - tip).norm_squared(), 0.012);
        d.x += eyes
            * (gauss((o - left).norm_squared(), 0.012) - gauss((o - right).norm_squared(), 0.012));
        *q = o + d;
    }
    out
}

/// A camera 0.5 m from the face, turned by `yaw_deg`, slightly above.
fn camera(yaw_deg: f64) -> Camera {
    let target = Vec3::new(0.0, 0.0, 0.03);
    let a = yaw_deg.to_radians();
    let c = target + Vec3::new(a.sin(), 0.05, a.cos()) * 0.5;
    let fwd = (target - c).normalize();
    let right = Vec3::new(0.0, -1.0, 0.0).cross(&fwd).normalize();
    let down = fwd.cross(&right);
    let r = Matrix3::from_rows(&[right.transpose(), down.transpose(), fwd.transpose()]);
    Camera::new(1000.0, 1000.0, 319.5, 239.5, r, -(r * c), 640, 480)
}

/// The `.pts` text (300-W: pixel centres at 1) of `mesh` seen by `cam`, with noise.
fn pts(mesh: &FaceMesh, cam: &Camera, rng: &mut SplitMix64) -> String {
    let sil = silhouette(mesh, cam);
    let mut s = String::from("version: 1\nn_points: 68\n{\n");
    for (i, p) in landmark_positions(mesh).iter().enumerate() {
        let mut q = cam.project(p).unwrap();
        if i <= 16 {
            q = sil.nearest(q).unwrap().image;
        }
        let (x, y) = (q[0] + 0.5 * rng.normal(), q[1] + 0.5 * rng.normal());
        s.push_str(&format!("{:.3} {:.3}\n", x + 1.0, y + 1.0));
    }
    s.push_str("}\n");
    s
}

/// A plain 640×480 grey photo, PNG or (hand-written) PPM by the extension of `path`.
fn write_photo(path: &Path) {
    if path.extension().unwrap() == "ppm" {
        let mut b = b"P6\n640 480\n255\n".to_vec();
        b.resize(b.len() + 640 * 480 * 3, 128);
        std::fs::write(path, b).unwrap();
    } else {
        image::RgbImage::from_pixel(640, 480, image::Rgb([128, 128, 128]))
            .save(path)
            .unwrap();
    }
}

const PEOPLE: [(&str, [f64; 4]); 4] = [
    ("alice", [1.00, 1.00, 0.000, 0.000]),
    ("bob", [1.15, 1.10, 0.010, 0.004]),
    ("carol", [0.90, 0.92, -0.006, -0.003]),
    ("dave", [1.08, 0.88, 0.006, 0.005]),
];
const VIEWS: [(&str, f64); 3] = [("front", 0.0), ("left", 35.0), ("right", -35.0)];

/// The four people's photos in one folder `mixed` (alice and bob by name, carol and dave in
/// subfolders), and each person alone in `alone/<name>/` (stems `front`, `left`, `right`).
fn make_folders(root: &Path, g: &FaceMesh) -> (PathBuf, PathBuf) {
    let (mixed, alone) = (root.join("mixed"), root.join("alone"));
    let mut rng = SplitMix64::new(47);
    for (name, [w, l, n, e]) in PEOPLE {
        let face = person(g, w, l, n, e);
        let ext = if name == "bob" { "ppm" } else { "png" };
        let by_folder = name == "carol" || name == "dave";
        for (view, yaw) in VIEWS {
            let text = pts(&face, &camera(yaw), &mut rng);
            let (dir, stem) = if by_folder {
                (mixed.join(name), view.to_string())
            } else {
                (mixed.clone(), format!("{name}_{view}"))
            };
            let solo = alone.join(name);
            for (d, s) in [(dir, stem), (solo, view.to_string())] {
                std::fs::create_dir_all(&d).unwrap();
                write_photo(&d.join(format!("{s}.{ext}")));
                std::fs::write(d.join(format!("{s}.pts")), &text).unwrap();
            }
        }
    }
    (mixed, alone)
}

fn run_script(sets: &[String]) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_emilion"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", "scripts/face_fit.rhai"]);
    for s in sets {
        c.args(["--set", s]);
    }
    let o = c.output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn four_peoples_photos_give_four_people_each_fitted_as_well_as_alone() {
    let Ok(g) = FaceMesh::mediapipe() else {
        println!("skipped: the MediaPipe face is not in the shared data (EMILION_DATA)");
        return;
    };
    let root = temp("four");
    let (mixed, alone) = make_folders(&root, &g);
    let opts = AdaptOptions::default();

    // each person alone: a folder of one person's views is one person
    let mut alone_err = Vec::new();
    for (name, _) in PEOPLE {
        let fits = fit_people(
            &alone.join(name),
            None,
            &root.join("out_alone").join(name),
            Grouping::default(),
            &opts,
            128,
        )
        .unwrap();
        assert_eq!(fits.len(), 1, "{name}");
        assert_eq!(fits[0].name, name);
        assert_eq!(fits[0].report.names, ["front", "left", "right"]);
        alone_err.push(fits[0].report.mean_error_iod_pct());
    }

    // the mixed folder through the script: four people, three photos each
    let out = root.join("out_mixed");
    let (ok, stdout, stderr) = run_script(&[
        format!("images={}", mixed.display()),
        format!("out={}", out.display()),
        "texture_size=128".into(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    println!("{stdout}");
    assert!(stdout.lines().any(|l| l == "people=4"), "{stdout}");
    assert!(
        stdout.lines().last().unwrap().ends_with(" images=12"),
        "{stdout}"
    );
    let people_csv = std::fs::read_to_string(out.join("people.csv")).unwrap();
    let rows: Vec<Vec<&str>> = people_csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 4, "{people_csv}");
    for (row, ((name, _), alone)) in rows.iter().zip(PEOPLE.iter().zip(&alone_err)) {
        assert_eq!(row[0], *name, "{people_csv}");
        assert_eq!(row[1], "3", "{people_csv}");
        let err: f64 = row[2].parse().unwrap();
        println!("{name}: {err:.3} % of the IOD in the mixed folder, {alone:.3} % alone");
        assert!(
            err <= 1.0 && (err - alone).abs() <= 0.05 * alone.max(0.1),
            "{name}: {err} vs {alone}"
        );
        assert!(out.join(name).join("face.obj").is_file(), "{name}");
        assert!(out.join(name).join("fit.csv").is_file(), "{name}");
    }
    let photos_csv = std::fs::read_to_string(out.join("photos.csv")).unwrap();
    assert_eq!(photos_csv.lines().count(), 13, "{photos_csv}");
    assert!(
        photos_csv.contains("\nbob,bob_left,") && photos_csv.contains("\ncarol,front,"),
        "{photos_csv}"
    );

    // all twelve photos as one face (the old rule) mixes the people: clearly worse
    let flat = root.join("flat");
    std::fs::create_dir_all(&flat).unwrap();
    for e in std::fs::read_dir(&alone).unwrap() {
        let person = e.unwrap().path();
        let name = person.file_name().unwrap().to_str().unwrap().to_string();
        for f in std::fs::read_dir(&person).unwrap() {
            let f = f.unwrap().path();
            let to = flat.join(format!(
                "{name}-{}",
                f.file_name().unwrap().to_str().unwrap()
            ));
            std::fs::copy(&f, to).unwrap();
        }
    }
    let one = fit_people(
        &flat,
        None,
        &root.join("out_flat"),
        Grouping::Folder,
        &opts,
        128,
    )
    .unwrap();
    assert_eq!(one.len(), 1);
    let mixed_err = one[0].report.mean_error_iod_pct();
    let worst_alone = alone_err.iter().copied().fold(0.0, f64::max);
    println!("all 12 photos as one face: {mixed_err:.3} % of the IOD (worst person alone {worst_alone:.3} %)");
    assert!(
        mixed_err > 2.0 * worst_alone,
        "{mixed_err} vs {worst_alone}"
    );
}

#[test]
fn photos_group_by_subfolder_name_or_photo() {
    let Ok(g) = FaceMesh::mediapipe() else {
        println!("skipped: the MediaPipe face is not in the shared data (EMILION_DATA)");
        return;
    };
    let root = temp("groups");
    let (mixed, _) = make_folders(&root, &g);
    let names = |people: &[emilion::face::people::PersonPhotos]| -> Vec<String> {
        people
            .iter()
            .map(|p| format!("{}:{}", p.name, p.photos.len()))
            .collect()
    };
    let by_name = group_people(&mixed, None, Grouping::Names).unwrap();
    assert_eq!(names(&by_name), ["alice:3", "bob:3", "carol:3", "dave:3"]);
    let per_photo = group_people(&mixed, None, Grouping::Photo).unwrap();
    assert_eq!(per_photo.len(), 12);
    assert_eq!(per_photo[0].name, "alice_front");
    assert!(per_photo.iter().any(|p| p.name == "carol/left"));
    // the top folder only, as one person named after it
    let folder = group_people(&mixed, None, Grouping::Folder).unwrap();
    assert_eq!(names(&folder), ["mixed:6"]);
    // per_photo and a bad group from the script
    let out = root.join("out");
    let (ok, stdout, stderr) = run_script(&[
        format!("images={}", mixed.join("carol").display()),
        format!("out={}", out.display()),
        "texture_size=64".into(),
        "per_photo=true".into(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.lines().any(|l| l == "people=3"), "{stdout}");
    assert!(out.join("front").join("face.glb").is_file());
    let (ok, _, stderr) = run_script(&[
        format!("images={}", mixed.display()),
        format!("out={}", out.display()),
        "group=people".into(),
    ]);
    assert!(
        !ok && stderr.contains("group") && stderr.contains("people"),
        "{stderr}"
    );
}
