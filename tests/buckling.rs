//! Euler buckling and post-buckling of a compressed strip against the analytic answers of the
//! maths notes §5.3 (the pinned elastica table), Choi & Ko's immediate-buckling force
//! against the same elastica, and the compression-release model on a garment pattern's
//! triangle mesh.

use std::sync::Arc;

use emilion::cloth::buckling::choi_ko::buckling_force;
use emilion::cloth::buckling::compression_release::{CompressionRelease, ReleaseOptions};
use emilion::cloth::constraints::ParticleFilter;
use emilion::cloth::{ClothModel, FabricParameters, Filter, MaterialLaw, Obstacles, StepStage};
use emilion::garment::mesh::patch::rectangle_mesh;
use emilion::kes::compression::{Strip, StripEnds, StripState};

/// B of the test strips (N·m): a light shirting.
const B: f64 = 1e-5;

/// The pinned–pinned elastica, maths notes §5.3: (end rotation °, P/P_cr, Δ/L, w_mid/L).
const ELASTICA: [(f64, f64, f64, f64); 8] = [
    (5.0, 1.00095, 0.00190, 0.02776),
    (10.0, 1.00382, 0.00760, 0.05538),
    (20.0, 1.01540, 0.03027, 0.10971),
    (30.0, 1.03512, 0.06757, 0.16195),
    (45.0, 1.08154, 0.14934, 0.23426),
    (60.0, 1.15172, 0.25898, 0.29660),
    (90.0, 1.39320, 0.54305, 0.38138),
    (120.0, 1.88480, 0.87684, 0.40159),
];

fn strip(ends: StripEnds) -> Strip {
    let fabric = FabricParameters {
        bend_warp: B,
        bend_weft: B,
        stretch_warp: 1e4,
        stretch_weft: 1e4,
        ..FabricParameters::default()
    };
    let law: Arc<dyn MaterialLaw> = Arc::new(fabric.linear_law());
    Strip {
        law,
        length: 0.1,
        width: 0.01,
        cells: 60,
        ends,
    }
}

/// Linear interpolation of `y(x)` on a path sorted by x.
fn at(path: &[StripState], x: f64, fx: fn(&StripState) -> f64, fy: fn(&StripState) -> f64) -> f64 {
    let k = path
        .iter()
        .position(|p| fx(p) >= x)
        .expect("path reaches x");
    assert!(k > 0, "path starts beyond {x}");
    let (a, b) = (&path[k - 1], &path[k]);
    let t = (x - fx(a)) / (fx(b) - fx(a));
    fy(a) + t * (fy(b) - fy(a))
}

/// The load at the onset: the first buckled equilibrium (a deflection of 1–3 % of the length,
/// end rotations of about 2–6° when pinned) brought back to zero shortening along the
/// elastica's own slope P/P_cr ≈ 1 + Δ/(2L).
fn onset_load(path: &[StripState]) -> f64 {
    let p = path
        .iter()
        .find(|p| p.deflection > 0.01)
        .expect("the strip buckles");
    assert!(p.deflection < 0.03, "increments too coarse");
    p.load / (1.0 + 0.5 * p.shortening)
}

#[test]
fn pinned_strip_buckles_at_the_euler_load_and_follows_the_elastica() {
    let s = strip(StripEnds::Pinned);
    let pcr = s.euler_load(B);
    let path = s.compress(B, 0.3, 60).unwrap();
    assert!(path.iter().all(|p| p.converged));
    let onset = onset_load(&path);
    eprintln!("pinned: onset load {:.4} P_cr", onset / pcr);
    assert!(
        (onset / pcr - 1.0).abs() < 0.10,
        "onset {} P_cr",
        onset / pcr
    );
    // force–shortening curve against the table, up to an end rotation of 60°
    for &(alpha, p_ratio, short, w) in ELASTICA.iter().filter(|r| r.0 <= 60.0) {
        let p = at(&path, short, |p| p.shortening, |p| p.load) / pcr;
        let a = at(&path, short, |p| p.shortening, |p| p.end_rotation).to_degrees();
        let wm = at(&path, short, |p| p.shortening, |p| p.deflection);
        eprintln!(
            "Δ/L {short:.5}: P/P_cr {p:.4} (elastica {p_ratio}), α {a:.1}° ({alpha}°), w/L {wm:.4} ({w})"
        );
        assert!(
            (p / p_ratio - 1.0).abs() < 0.10,
            "Δ/L {short}: P/P_cr {p} vs {p_ratio}"
        );
        assert!(
            (a - alpha).abs() < 0.1 * alpha,
            "Δ/L {short}: α {a}° vs {alpha}°"
        );
        assert!((wm / w - 1.0).abs() < 0.10, "Δ/L {short}: w/L {wm} vs {w}");
    }
}

#[test]
fn clamped_strip_buckles_at_four_times_the_pinned_load() {
    let s = strip(StripEnds::Clamped);
    let pcr = s.euler_load(B);
    let path = s.compress(B, 0.02, 40).unwrap();
    assert!(path.iter().all(|p| p.converged));
    let onset = onset_load(&path);
    eprintln!("clamped: onset load {:.4} P_cr (4π²B/L²)", onset / pcr);
    assert!(
        (onset / pcr - 1.0).abs() < 0.10,
        "onset {} P_cr",
        onset / pcr
    );
}

#[test]
fn strip_stays_straight_below_the_critical_load_and_buckles_above() {
    let s = strip(StripEnds::Pinned);
    let pcr = s.euler_load(B);
    let below = s.load(B, 0.9 * pcr, 20).unwrap();
    let above = s.load(B, 1.1 * pcr, 20).unwrap();
    eprintln!(
        "0.9 P_cr: w/L {:.5}, α {:.2}°; 1.1 P_cr: w/L {:.4}, α {:.1}°",
        below.deflection,
        below.end_rotation.to_degrees(),
        above.deflection,
        above.end_rotation.to_degrees()
    );
    assert!(below.converged && above.converged);
    // below: only the imperfection's amplified bow, 1/1000 of P_cr at mid-span
    assert!(
        below.deflection < 0.005,
        "0.9 P_cr: w/L {}",
        below.deflection
    );
    // above: on the elastica, P/P_cr = 1.1 between the 45° and 60° rows (w/L 0.234–0.297)
    assert!(
        above.deflection > 0.22 && above.deflection < 0.31,
        "1.1 P_cr: w/L {}",
        above.deflection
    );
}

#[test]
fn choi_ko_force_is_stiffer_than_the_elastica_by_its_arc_kinematics() {
    // one connection of length L standing for the whole pinned strip: its chord shortening is
    // the end shortening; onset 12 k_b/L² = 1.216 π² k_b/L²
    let (kb, l) = (B * 0.01, 0.1);
    let euler = std::f64::consts::PI.powi(2) * kb / (l * l);
    let (f0, _) = buckling_force(kb, l, l * (1.0 - 1e-9));
    assert!(
        (-f0 / (12.0 * kb / (l * l)) - 1.0).abs() < 1e-6,
        "onset {f0}"
    );
    let mut worst: f64 = 0.0;
    for &(alpha, p_ratio, short, _) in ELASTICA.iter().filter(|r| r.0 <= 60.0) {
        let (f, _) = buckling_force(kb, l, l * (1.0 - short));
        let dev = -f / (p_ratio * euler) - 1.0;
        eprintln!(
            "α {alpha}°: Choi–Ko {:.4} P_cr, elastica {p_ratio}: {:+.1} %",
            -f / euler,
            dev * 100.0
        );
        worst = worst.max(dev);
        assert!(dev > 0.0, "Choi–Ko is never softer than the elastica");
    }
    eprintln!("largest deviation up to 60°: {:.1} %", worst * 100.0);
    // the maths notes: 20–30 % stiffer; more would be a bug in the force
    assert!(worst > 0.15 && worst < 0.32, "deviation {worst}");
}

/// Runs `scripts/buckle_square.rhai` with `sets` into a fresh folder; returns its printed
/// report lines and the folder.
fn buckle_square(tag: &str, sets: &[(&str, &str)]) -> (Vec<String>, std::path::PathBuf) {
    run_script("buckle_square", tag, sets)
}

/// Runs `scripts/NAME.rhai` with `sets` into a fresh folder; returns the lines it printed
/// that start with NAME, and its output folder.
fn run_script(name: &str, tag: &str, sets: &[(&str, &str)]) -> (Vec<String>, std::path::PathBuf) {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("buckling")
        .join(tag);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let exe = env!("CARGO_BIN_EXE_emilion");
    let mut cmd = std::process::Command::new(exe);
    cmd.arg("run")
        .arg(format!(
            "{}/scripts/{name}.rhai",
            env!("CARGO_MANIFEST_DIR")
        ))
        .arg("--set")
        .arg(format!("out={}", out.display()));
    for (k, v) in sets {
        cmd.arg("--set").arg(format!("{k}={v}"));
    }
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines = String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.starts_with(name))
        .map(str::to_string)
        .collect();
    (lines, out.join(name))
}

/// Runs a cylinder scene (`buckle_cylinder` or `buckle_sleeve`) with `sets`; returns its
/// three report lines (none, Choi–Ko, release), checked to name their models and to leave no
/// vertex inside the cylinder, and its output folder.
fn run_cylinder_scene(
    name: &str,
    tag: &str,
    sets: &[(&str, &str)],
) -> ([String; 3], std::path::PathBuf) {
    let (l, dir) = run_script(name, tag, sets);
    for x in &l {
        eprintln!("{x}");
    }
    let l: [String; 3] = l.try_into().unwrap_or_else(|l| panic!("{l:?}"));
    for (x, model) in l.iter().zip([" none:", " choi_ko:", " release:"]) {
        assert!(x.contains(model), "{x}");
        assert_eq!(field(x, "inside"), 0.0, "{x}");
    }
    (l, dir)
}

/// The number after `key` in a report line.
fn field(line: &str, key: &str) -> f64 {
    let rest = &line[line.find(key).unwrap_or_else(|| panic!("{key} in {line}")) + key.len()..];
    rest.trim_start()
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn pushed_square_wrinkles_with_choi_ko_and_repeats_bit_for_bit() {
    let (a, dir_a) = buckle_square("seed42a", &[("seed", "42")]);
    let (b, dir_b) = buckle_square("seed42b", &[("seed", "42")]);
    assert_eq!(a.len(), 3, "{a:?}");
    // the same seed gives the same report (timings aside)
    let strip = |l: &String| l[..l.find(" J,").unwrap()].to_string();
    assert_eq!(
        a.iter().map(strip).collect::<Vec<_>>(),
        b.iter().map(strip).collect::<Vec<_>>()
    );
    for l in &a {
        eprintln!("{l}");
    }
    let (none, ck) = (&a[0], &a[1]);
    assert!(none.contains(" none:") && ck.contains(" choi_ko:"));
    // Choi–Ko: at most 1 % of the springs compressed by more than 1 %, and wrinkles
    assert!(field(ck, "compressed >1%:") / 3280.0 <= 0.01);
    assert!(field(ck, "half-waves") >= 2.0);
    // (the final spring energies are printed, not compared: lower with Choi–Ko at 41² but
    // higher at 64², so this weightless set-up does not settle that acceptance line)
    // the same seed gives bit-identical cloths
    for m in ["none", "choi_ko", "release"] {
        let (p, q) = (
            dir_a.join(format!("{m}.obj")),
            dir_b.join(format!("{m}.obj")),
        );
        assert_eq!(std::fs::read(p).unwrap(), std::fs::read(q).unwrap(), "{m}");
    }
    assert!(dir_a.join("energy.png").exists() && dir_a.join("energy.csv").exists());
}

#[test]
fn flat_pushed_square_stays_compressed_without_a_model_and_buckles_with_either_model() {
    // no imperfection: nothing pushes the cloth out of its plane but the buckling model
    let (l, _) = buckle_square("flat", &[("imperfection", "0.0")]);
    for x in &l {
        eprintln!("{x}");
    }
    let (none, ck, rel) = (&l[0], &l[1], &l[2]);
    assert!(rel.contains(" release:"));
    // without a model it stays flat and keeps its compression energy
    assert_eq!(field(none, "half-waves"), 0.0);
    // compression release: at most 1 % of the springs compressed by more than 1 %, wrinkles,
    // and far less spring energy than without a model
    assert!(field(rel, "compressed >1%:") / 3280.0 <= 0.01, "{rel}");
    assert!(field(rel, "half-waves") >= 2.0, "{rel}");
    assert!(
        field(rel, "elastic") < 0.1 * field(none, "elastic"),
        "{none}\n{rel}"
    );
    // Choi–Ko: a compressed connection in the flat cloth bulges to a seeded side, so it
    // leaves the plane and wrinkles as well (before, it stayed flat and folded over itself in
    // its plane: the middle row reached 0.19 m, past the pushed border at 0.15 m)
    assert!(field(ck, "compressed >1%:") / 3280.0 <= 0.01, "{ck}");
    assert!(field(ck, "half-waves") >= 2.0, "{ck}");
    assert!(field(ck, "amplitude") > 0.01, "{ck}");
    assert!(
        field(ck, "elastic") < 0.1 * field(none, "elastic"),
        "{none}\n{ck}"
    );
}

#[test]
fn choi_ko_flat_square_buckles_to_the_seeded_side_regression() {
    // the same seed gives the same wrinkles bit for bit, other seeds other wrinkles
    let run = |tag: &str, seed: &str| {
        let (l, dir) = buckle_square(tag, &[("imperfection", "0.0"), ("seed", seed)]);
        (
            l[1].clone(),
            std::fs::read(dir.join("choi_ko.obj")).unwrap(),
        )
    };
    let (a, obj_a) = run("ck_seed_a", "3");
    let (_, obj_b) = run("ck_seed_b", "3");
    let (c, obj_c) = run("ck_seed_c", "4");
    assert!(obj_a == obj_b, "same seed, different result");
    assert!(obj_a != obj_c, "{a}\n{c}");
    assert!(field(&c, "half-waves") >= 2.0, "{c}");
}

#[test]
fn flat_triangle_mesh_pushed_from_one_border_is_released_by_both_models() {
    // the same square as a triangle mesh of irregular triangles (hinges, no grid lines),
    // perfectly flat: without a model it stays flat and compressed until round-off lets it
    // snap out of its plane late in the push
    let (l, dir) = buckle_square("mesh_flat", &[("imperfection", "0.0"), ("mesh", "true")]);
    for x in &l {
        eprintln!("{x}");
    }
    let (none, ck, rel) = (&l[0], &l[1], &l[2]);
    assert!(rel.contains(" release:"));
    let springs = |x: &String| {
        let s = &x[x.find('/').unwrap() + 1..];
        s[..s.find(' ').unwrap()].parse::<f64>().unwrap()
    };
    assert!(springs(rel) > 5000.0, "{rel}");
    // compression release: at most 1 % of the springs compressed by more than 1 %, wrinkles,
    // and far less spring energy over the push than without a model
    assert!(
        field(rel, "compressed >1%:") / springs(rel) <= 0.01,
        "{rel}"
    );
    assert!(field(rel, "half-waves") >= 2.0, "{rel}");
    assert!(
        field(rel, "mean over the run") < 0.25 * field(none, "mean over the run"),
        "{none}\n{rel}"
    );
    // Choi–Ko: the flat connections bulge to seeded sides, so the mesh leaves its plane too
    // (before, it stayed flat with 51.5 % of its springs compressed and 4.5 J stored)
    assert!(field(ck, "compressed >1%:") / springs(ck) <= 0.01, "{ck}");
    assert!(field(ck, "half-waves") >= 2.0, "{ck}");
    assert!(
        field(ck, "mean over the run") < 0.25 * field(none, "mean over the run"),
        "{none}\n{ck}"
    );
    // regression: both models end with less spring energy than the creased mesh. A flat
    // cloth's ties were drawn for each particle (release) or connection (Choi–Ko) on its own,
    // so neighbours bulged opposite ways and the mesh ended creased: release 0.0074 J,
    // Choi–Ko 4.5e-4 J. One side per step: 1.0e-4 and 2.5e-4 J. The bound is the 4.2e-4 J the
    // run without a model ended with while its snap out of the plane blew up (2.85 J → 91.9 J
    // in three steps); the step guard (issue 48) now retries that step in substeps, so that
    // run is no longer a reference.
    for x in [ck, rel] {
        assert!(field(x, "elastic") < 4.2e-4, "{none}\n{x}");
    }
    assert!(dir.join("mesh_energy.png").exists() && dir.join("mesh_release_24.png").exists());
}

#[test]
fn cloth_pushed_along_a_cylinder_is_released_by_compression_release() {
    let (l, dir) = run_cylinder_scene("buckle_cylinder", "cylinder", &[]);
    let (none, rel) = (&l[0], &l[2]);
    // compression release: at most 1 % of the springs compressed by more than 1 %, less
    // spring energy at the end than without a model (the figure was the mean over the resting
    // frames while contacts chattered; since contacts come to rest the energies decay
    // smoothly after the push, and the one at the end is the acceptance's figure)
    assert!(field(rel, "compressed >1%:") / 3280.0 <= 0.01, "{rel}");
    assert!(
        field(rel, "elastic") < field(none, "elastic"),
        "{none}\n{rel}"
    );
    // regression: and over the resting frames. A particle well off its neighbours' plane
    // whose near destination lay in the cylinder jumped to the far one, through the cloth
    // (up to 1.36 rest lengths), and kicked it at rest: the resting mean was 0.0177 J against
    // 0.0155 J without a model, and the state after the last step held 0.046 J on one seed
    assert!(
        field(rel, "resting mean") < field(none, "resting mean"),
        "{none}\n{rel}"
    );
    assert!(dir.join("energy.png").exists() && dir.join("release_24.png").exists());
}

/// The seed report's cylinder experiment as it words it: a sleeve with the cylinder inside,
/// pushed along it. Both models end with less spring energy than no model (seed figs. 33–34).
/// With a 0.1 mm imperfection along the axis, seeds 1–6 (2026-12-05): no model 0.049–0.057 J,
/// compression release below it on all six (mean 0.0323 J), Choi–Ko on five (mean 0.0514
/// against 0.0533 J).
#[test]
fn sleeve_pushed_along_its_cylinder_ends_with_less_energy_with_either_model() {
    let (l, dir) = run_cylinder_scene("buckle_sleeve", "sleeve", &[]);
    let (none, ck, rel) = (&l[0], &l[1], &l[2]);
    for m in [ck, rel] {
        assert!(field(m, "elastic") < field(none, "elastic"), "{none}\n{m}");
    }
    // regression: compression release relieves the tube's compression (102 springs compressed
    // by more than 1 % against 189 without a model). Releases that strained the particle's
    // ring were refused rather than settled, 98 % of them on this mesh: 181 were left
    // compressed, and the tube ended at 0.052 J against 0.056 J
    assert!(
        field(rel, "compressed >1%:") < 0.7 * field(none, "compressed >1%:"),
        "{none}\n{rel}"
    );
    assert!(dir.join("energy.png").exists() && dir.join("release_24.png").exists());
}

/// With cloth–cloth collisions on, a release never carries a particle through another layer of
/// the sleeve, nor drives it on into one. Its hold was a hard constraint the cloth–cloth
/// response could not move: released particles went through the layers folded over them
/// (86 intersecting edge–triangle pairs at the end, a peak of 2.4 J against 0.20 J without a
/// model). Made to yield but still held for its steps, a stopped particle was driven into the
/// layer again each step (no crossing, but a peak of 1.5 J and 0.75 J at the end).
#[test]
fn release_never_carries_a_particle_through_the_cloth_regression() {
    let (l, _) = run_cylinder_scene(
        "buckle_sleeve",
        "sleeve_self_collision",
        &[("self_collision", "true")],
    );
    for x in &l {
        assert_eq!(field(x, "self-intersecting pairs"), 0.0, "{x}");
    }
    let (none, rel) = (&l[0], &l[2]);
    assert!(
        field(rel, "peak") < 2.0 * field(none, "peak"),
        "{none}\n{rel}"
    );
}

/// The wrinkles of a sheet stretched along x and compressed along y: their wavelength follows
/// the tension-set scaling λ = 2π (B L²/(π² T))^(1/4) of Cerda & Mahadevan, within the
/// quantisation of a whole number of half-waves between the held borders.
#[test]
fn wrinkle_wavelength_grows_as_the_fourth_root_of_bending_rigidity() {
    for model in ["release", "none"] {
        let (l, dir) = run_script("wrinkle_wavelength", model, &[("model", model)]);
        for x in &l {
            eprintln!("{x}");
        }
        assert_eq!(l.len(), 3, "{l:?}");
        let lambda: Vec<f64> = l.iter().map(|x| field(x, ", wavelength")).collect();
        let predicted: Vec<f64> = l.iter().map(|x| field(x, "predicted")).collect();
        for (m, p) in lambda.iter().zip(&predicted) {
            assert!((m / p - 1.0).abs() < 0.25, "{model}: λ {m} m against {p} m");
        }
        // B grows 16-fold from the first run to the last: λ should double
        let slope = (lambda[2] / lambda[0]).ln() / 16f64.ln();
        assert!((slope - 0.25).abs() < 0.06, "{model}: λ ∝ B^{slope}");
        assert!(dir.join(format!("{model}.png")).exists());
    }
}

#[test]
fn choi_ko_wrinkle_wavelength_grows_with_bending_rigidity_regression() {
    // Choi–Ko's connections used to read the fabric's stretch as less bending and push the
    // membrane apart with at least 12 B/L² wherever the cloth was bent: the wrinkles then kept
    // about 8.5 grid spacings whatever B (0.070 / 0.070 / 0.075 m, λ ∝ B^0.03). With the arc
    // as long as the fabric (`cloth::arc_connection`) they follow B again (theory: B^0.25).
    let (l, _) = run_script("wrinkle_wavelength", "choi_ko", &[("model", "choi_ko")]);
    for x in &l {
        eprintln!("{x}");
    }
    assert_eq!(l.len(), 3, "{l:?}");
    let lambda: Vec<f64> = l.iter().map(|x| field(x, ", wavelength")).collect();
    assert!(lambda[0] < lambda[1] && lambda[1] < lambda[2], "{lambda:?}");
    let slope = (lambda[2] / lambda[0]).ln() / 16f64.ln();
    assert!(slope > 0.15, "Choi–Ko: λ ∝ B^{slope}");
}

#[test]
fn nearly_flat_mesh_release_does_not_compress_the_rest_of_the_ring_regression() {
    // a 1e-9 m imperfection: released particles whose three spheres compressed the other
    // springs of their ring left 1.4 % of the springs compressed by more than 1 %; a release
    // must now lower its ring's compression
    let (l, _) = buckle_square(
        "mesh_near_flat",
        &[("imperfection", "1e-9"), ("mesh", "true")],
    );
    let rel = &l[2];
    eprintln!("{rel}");
    assert!(rel.contains(" release:"));
    assert!(field(rel, "compressed >1%:") / 5651.0 <= 0.01, "{rel}");
}

// the compression-release model on a triangle mesh (a garment pattern's mesher makes it)

#[test]
fn a_release_settles_its_whole_ring_regression() {
    // Refusing releases that strained the ring (three springs back at rest, the others
    // stretched) left the sleeve of `scripts/buckle_sleeve.rhai` with 5 % of its springs
    // compressed: 98 % of its releases were refused, and it ended at 0.052 J against 0.056 J
    // without a model. A triangle mesh compressed 20 % along one axis and 5 % across: the
    // three spheres bring three springs of six back to rest and stretch the others; the
    // settled destinations lower every released particle's ring strain to a fraction of it.
    let mesh = rectangle_mesh(0.2, 0.1, 0.02).unwrap();
    let mut model = ClothModel::from_mesh(mesh, FabricParameters::default()).unwrap();
    model.prestrain(-0.2, -0.05);
    let x = model.mesh.positions.clone();
    let mut cr = CompressionRelease::new(&model, ReleaseOptions::default());
    let mut filter = Filter::new(x.len());
    cr.constrain(&x, &x, 0.0, 0.01, &mut filter, Obstacles::none());
    let mut released = 0;
    for (m, k) in filter.kind.iter().enumerate() {
        let ParticleFilter::Fixed { target } = k else {
            continue;
        };
        released += 1;
        let (before, after) = (cr.ring_strain(&x, m, &x[m]), cr.ring_strain(&x, m, target));
        assert!(after < 0.5 * before, "particle {m}: {before} → {after}");
    }
    // the interior particles away from each other's rings (the border has no ring across)
    assert!(released >= 4, "{released}");
}

#[test]
fn a_compressed_triangle_mesh_releases_out_of_its_plane() {
    let mesh = rectangle_mesh(0.2, 0.1, 0.02).unwrap();
    let mut model = ClothModel::from_mesh(mesh, FabricParameters::default()).unwrap();
    assert!(model.grid.is_none());
    model.prestrain(-0.2, 0.0);
    let x = model.mesh.positions.clone();
    let (mut up, mut down) = (0, 0);
    for seed in 0..8 {
        let options = ReleaseOptions {
            seed,
            ..Default::default()
        };
        let mut cr = CompressionRelease::new(&model, options);
        let mut filter = Filter::new(x.len());
        cr.constrain(&x, &x, 0.0, 0.01, &mut filter, Obstacles::none());
        assert!(cr.releases > 0);
        for (m, k) in filter.kind.iter().enumerate() {
            let ParticleFilter::Fixed { target } = k else {
                continue;
            };
            // off the plane, and its ring less strained
            assert!(target.z.abs() > 1e-3, "{target}");
            assert!(cr.ring_strain(&x, m, target) < cr.ring_strain(&x, m, &x[m]));
            if target.z > 0.0 {
                up += 1;
            } else {
                down += 1;
            }
        }
    }
    assert!(up > 0 && down > 0, "{up} up, {down} down");
}
