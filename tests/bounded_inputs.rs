//! Tiny inputs that asked for gigabytes, wrong results reported as success, and readers that
//! read a file whole without a bound (issue 48): each case, written by the test into a temp
//! folder, now gives a clear error naming the file, line or parameter and the limit, within
//! seconds and modest memory.
//!
//! The limits are process-wide; every test here runs with the defaults except
//! `max_file_bytes`, lowered to 16 MiB for the whole test binary ([`limits`]) so that reading
//! `/dev/zero` stops after 16 MiB instead of the default 1 GiB. Nothing here depends on that
//! limit being larger.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Once;

use emilion::facade::facade_mesh::MeshParams;
use emilion::facade::outputs::{write_generated, OutputOptions};
use emilion::facade::rule_file::{read_rules, MAX_FACADE_METRES};
use emilion::kes::{lab, read_fabric, KesParam};

const SMALL_FILE_LIMIT: u64 = 16 << 20;

/// Sets the limits this test binary runs with (the same for every test).
fn limits() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        emilion::limits::set(emilion::limits::Limits {
            max_file_bytes: SMALL_FILE_LIMIT,
            ..Default::default()
        });
    });
}

fn temp(name: &str) -> PathBuf {
    limits();
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("bounded_inputs")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Runs `emilion run script --set out=OUT` under a 4 GB address-space limit and 60 s;
/// returns (success, stdout + stderr).
fn run_binary(script: &Path, out: &Path) -> (bool, String) {
    let cmd = format!(
        "ulimit -v 4000000; exec timeout 60 '{}' run '{}' --set out='{}'",
        env!("CARGO_BIN_EXE_emilion"),
        script.display(),
        out.display()
    );
    let o = Command::new("sh").args(["-c", &cmd]).output().unwrap();
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &*String::from_utf8_lossy(&o.stderr);
    (o.status.success(), text)
}

// ---------------------------------------------------------------- facade rule files

/// The reported 118-byte rule files, each a facade that asked for gigabytes.
const TINY_REPEAT: &str = "// axiom F size 430 300\nF --> repeat(y, 0.0000001) { W }\nW --> wall\n";
const HUGE_SIZE: &str = "// axiom F size 1e300 300\nF --> repeat(x, 43) { W }\nW --> wall\n";
const TEN_WINDOWS: &str = "// axiom F size 430 300\nF --> repeat(x, 43) { W }\nW --> window\n";

#[test]
fn facade_rule_file_with_a_tiny_repeat_is_refused_before_deriving() {
    let dir = temp("tiny_repeat");
    let rules = write(&dir, "rep.cga", TINY_REPEAT);
    let e = read_rules(&rules).unwrap_err().to_string();
    // 300 / 1e-7 = 3e9 tiles, counted before any is made
    for want in ["rep.cga", "line 2", "rule F", "3000000000", "max_elements"] {
        assert!(e.contains(want), "{want}: {e}");
    }
}

#[test]
fn facade_rule_file_with_a_huge_size_is_refused_with_its_line() {
    let dir = temp("huge_size");
    let rules = write(&dir, "big.cga", HUGE_SIZE);
    let e = read_rules(&rules).unwrap_err().to_string();
    for want in ["big.cga", "line 1", "1e300", "1e6"] {
        assert!(e.contains(want), "{want}: {e}");
    }
    let fixed = write(
        &dir,
        "fixed.cga",
        "// axiom F size 10 10\nF --> split(x) { 2e9: W | ~1: W }\nW --> wall\n",
    );
    let e = read_rules(&fixed).unwrap_err().to_string();
    assert!(e.contains("line 2") && e.contains("size 2e9"), "{e}");
}

#[test]
fn facade_rule_file_whose_splits_multiply_is_refused_before_running_away() {
    // 40 rules, each split in two halves of the next: 2^40 shapes from a 2 KB file
    let dir = temp("split_chain");
    let mut text = String::from("// axiom R0 size 100 100\n");
    for k in 0..40 {
        text += &format!("R{k} --> split(x) {{ ~1: R{} | ~1: R{} }}\n", k + 1, k + 1);
    }
    text += "R40 --> wall\n";
    let rules = write(&dir, "chain.cga", text);
    let t = std::time::Instant::now();
    let e = read_rules(&rules).unwrap_err().to_string();
    assert!(e.contains("chain.cga") && e.contains("max_elements"), "{e}");
    assert!(t.elapsed().as_secs_f64() < 10.0, "{:?}", t.elapsed());
}

#[test]
fn facade_from_rules_with_a_huge_width_factor_is_refused() {
    let dir = temp("widths");
    let rules = write(&dir, "ok.cga", TEN_WINDOWS);
    let g = read_rules(&rules).expect("a plain rule file reads");
    // 430 / 43 = 10 tiles, each one window
    assert_eq!(g.derive(430.0, 300.0).unwrap().len(), 10);
    let params = MeshParams::new(0.01, g.size);
    let opts = OutputOptions {
        widths: vec![1e5],
        heights: vec![],
    };
    let out = dir.join("out");
    let e = write_generated(&g, &params, None, &out, "f", &opts)
        .unwrap_err()
        .to_string();
    // 430 units × 1e5 × 0.01 m = 430 km
    assert!(
        e.contains("`widths` factor 100000") && e.contains("430000") && e.contains("1000"),
        "{e}"
    );
    assert!(!out.exists(), "nothing is written");
    assert_eq!(MAX_FACADE_METRES, 1000.0);
    // the same file at its own width still makes its facade
    let files = write_generated(
        &g,
        &params,
        None,
        &out,
        "f",
        &OutputOptions {
            widths: vec![1.0],
            heights: vec![],
        },
    )
    .expect("1× is fine");
    assert!(files.iter().any(|f| f.ends_with("f_w1.obj")), "{files:?}");
}

#[test]
fn facade_rule_file_cases_fail_fast_in_the_release_binary() {
    let dir = temp("binary_rules");
    let out = dir.join("out");
    for (name, rules, opts) in [
        ("rep", TINY_REPEAT, "#{}"),
        ("big", HUGE_SIZE, "#{}"),
        ("widths", TEN_WINDOWS, "#{widths: [1e5]}"),
    ] {
        write(&dir, &format!("{name}.cga"), rules);
        let script = write(
            &dir,
            &format!("{name}.rhai"),
            format!("facade::from_rules(\"{name}.cga\", out, \"f\", {opts});\nprint(\"done\");\n"),
        );
        let t = std::time::Instant::now();
        let (ok, text) = run_binary(&script, &out);
        assert!(!ok && !text.contains("done"), "{name}: {text}");
        assert!(
            text.contains("max_elements") || text.contains("outside"),
            "{name}: {text}"
        );
        assert!(
            t.elapsed().as_secs_f64() < 20.0,
            "{name}: {:?}",
            t.elapsed()
        );
    }
}

// ---------------------------------------------------------------- images and rendering

/// A PNG header declaring `w × h` grey pixels, and a one-byte IDAT: what a reader sees first.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    fn crc(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut v = (data.len() as u32).to_be_bytes().to_vec();
        let body: Vec<u8> = kind.iter().chain(data).copied().collect();
        v.extend(&body);
        v.extend(crc(&body).to_be_bytes());
        v
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &[0]));
    png.extend(chunk(b"IEND", &[]));
    png
}

#[test]
fn photo_decoding_to_12000_squared_pixels_is_refused_from_its_header() {
    let dir = temp("big_png");
    let photo = write(&dir, "big.png", png_header(12000, 12000));
    let e = emilion::geometry::image::read_photo(&photo)
        .unwrap_err()
        .to_string();
    for want in [
        "big.png",
        "12000 × 12000",
        "144000000",
        "max_pixels = 100000000",
    ] {
        assert!(e.contains(want), "{want}: {e}");
    }
    // the facade analysis (and every other photo reader) goes through the same check
    let e = emilion::facade::analysis::analyze(&photo, &Default::default())
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("big.png") && e.contains("max_pixels"), "{e}");
    let e = emilion::facade::labels::LabelMap::read_labelmefacade(&photo)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_pixels"), "{e}");
    // a header within the limit gets past the check (and fails to decode its empty data)
    let small = write(&dir, "small.png", png_header(100, 100));
    let e = emilion::geometry::image::read_photo(&small)
        .unwrap_err()
        .to_string();
    assert!(!e.contains("max_pixels") && e.contains("decoded"), "{e}");
}

#[test]
fn render_at_100000_squared_is_an_error_not_a_silent_clamp() {
    let dir = temp("render");
    let out = dir.join("out");
    let script = write(
        &dir,
        "render.rhai",
        "let sim = simulation(cloth_grid(1.0, 1.0, 4, 4, fabric()), #{});\n\
         sim.render(out + \"/r.png\", #{width: 100000, height: 100000});\nprint(\"done\");\n",
    );
    let (ok, text) = run_binary(&script, &out);
    assert!(!ok && !text.contains("done"), "{text}");
    for want in ["`width` × `height`", "100000 × 100000", "max_pixels"] {
        assert!(text.contains(want), "{want}: {text}");
    }
    assert!(!out.join("r.png").exists());
    let zero = write(
        &dir,
        "zero.rhai",
        "let sim = simulation(cloth_grid(1.0, 1.0, 4, 4, fabric()), #{});\n\
         sim.render(out + \"/z.png\", #{width: 0});\n",
    );
    let (ok, text) = run_binary(&zero, &out);
    assert!(!ok && text.contains("`width` must be ≥ 1"), "{text}");
    // the library refuses it too, naming the file
    let cam = emilion::geometry::LookAtCamera {
        width: 16384,
        height: 16384,
        ..Default::default()
    };
    let e = emilion::render::render_png(&out.join("big.png"), &[], &cam)
        .unwrap_err()
        .to_string();
    assert!(e.contains("big.png") && e.contains("max_pixels"), "{e}");
}

// ---------------------------------------------------------------- KES values

/// The shipped shirting with the warp's `B` value replaced.
fn shirting_with_b(dir: &Path, name: &str, b: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo("kawabata/fabrics/shirting-cotton.json")).unwrap();
    let line = "\"B\": {\"value\": 0.09, \"unit\": \"gf.cm2/cm\"}";
    assert!(text.contains(line));
    let bad = text.replacen(
        line,
        &format!("\"B\": {{\"value\": {b}, \"unit\": \"gf.cm2/cm\"}}"),
        1,
    );
    write(dir, name, bad)
}

#[test]
fn kes_file_with_b_1e308_or_negative_is_refused_naming_the_field_and_range() {
    let dir = temp("kes");
    let e = read_fabric(&shirting_with_b(&dir, "huge_b.json", "1e308"))
        .unwrap_err()
        .to_string();
    for want in [
        "huge_b.json",
        "kes.warp.B",
        "1e308",
        "0.0001 … 10 gf.cm2/cm",
    ] {
        assert!(e.contains(want), "{want}: {e}");
    }
    let e = read_fabric(&shirting_with_b(&dir, "negative_b.json", "-0.09"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("negative_b.json") && e.contains("kes.warp.B") && e.contains("≥ 0"),
        "{e}"
    );
    let e = read_fabric(&shirting_with_b(&dir, "tiny_b.json", "1e-9"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("kes.warp.B"), "{e}");
    // a fabric built in code goes through the same ranges when it enters the lab
    let mut spec = read_fabric(&repo("kawabata/fabrics/shirting-cotton.json")).unwrap();
    spec.warp.set(KesParam::B, 1e308);
    let e = lab::run_fabric(&spec, &lab::LabOptions::default()).unwrap_err();
    assert!(
        e.contains("kes.warp.B") && e.contains("range of real fabrics"),
        "{e}"
    );
}

#[test]
fn every_shipped_and_measured_fabric_is_within_the_ranges() {
    let mut n = 0;
    for dir in ["kawabata/fabrics", "tests/data/fabrics_small"] {
        for f in emilion::kes::fabric::json_files(&repo(dir)).unwrap() {
            read_fabric(&f).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 3, "{n} fabrics");
    let wang = emilion::geometry::files::data_dir().join("fabrics/wang2011");
    if !wang.is_dir() {
        eprintln!(
            "skipped the Wang 2011 fabrics: {} is absent",
            wang.display()
        );
        return;
    }
    let out = temp("wang");
    let files = emilion::kes::import_wang_dir(&wang, &out).expect("every Wang fabric converts");
    assert_eq!(files.len(), 10);
    for f in files {
        read_fabric(&f).unwrap_or_else(|e| panic!("{e}"));
    }
}

// ---------------------------------------------------------------- face landmarks

fn pts(points: &[[f64; 2]]) -> String {
    let mut s = format!("version: 1\nn_points: {}\n{{\n", points.len());
    for p in points {
        s += &format!("{} {}\n", p[0], p[1]);
    }
    s + "}\n"
}

#[test]
fn identical_landmarks_are_an_error_not_a_nan_fit() {
    let dir = temp("face_identical");
    image::RgbImage::from_fn(400, 400, |x, y| {
        image::Rgb([(x % 256) as u8, (y % 256) as u8, 90])
    })
    .save(dir.join("p.png"))
    .unwrap();
    write(&dir, "p.pts", pts(&[[200.0, 200.0]; 68]));
    let out = dir.join("out");
    let e = emilion::face::fit_run::fit_folder(
        &dir,
        None,
        &out,
        &emilion::face::adapt::AdaptOptions::default(),
        256,
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(e.contains("p.pts") && e.contains("degenerate"), "{e}");
    assert!(!out.join("face.obj").exists());
    // through the release binary: exit 1, no NaN reported
    let script = write(
        &dir,
        "face.rhai",
        "let r = face_fit(\".\", out, #{});\nprint(r);\n",
    );
    let (ok, text) = run_binary(&script, &out);
    assert!(
        !ok && text.contains("p.pts") && !text.contains("NaN"),
        "{text}"
    );
}

#[test]
fn landmarks_on_a_line_or_too_close_are_degenerate_and_a_real_face_is_not() {
    use emilion::face::landmarks::{check_geometry, parse_pts};
    let line: Vec<[f64; 2]> = (0..68).map(|i| [10.0 + 3.0 * i as f64, 50.0]).collect();
    let e = check_geometry(&line, "line.pts").unwrap_err().to_string();
    assert!(e.contains("line.pts") && e.contains("on a line"), "{e}");
    let tiny: Vec<[f64; 2]> = (0..68)
        .map(|i| [50.0 + 0.01 * (i % 7) as f64, 50.0 + 0.01 * (i / 7) as f64])
        .collect();
    let e = check_geometry(&tiny, "tiny.pts").unwrap_err().to_string();
    assert!(e.contains("px apart"), "{e}");
    // the astronaut's landmarks, placed by hand on the photo, are a face
    let path = repo("tests/data/faces/astronaut.pts");
    let real = parse_pts(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    check_geometry(&real, "astronaut.pts").expect("a real face");
}

// ---------------------------------------------------------------- bounded reading

#[test]
fn dev_zero_and_oversized_files_are_refused_by_every_reader() {
    let dir = temp("dev_zero");
    // a sparse file one byte over the limit, and /dev/zero (no length, endless)
    let big = dir.join("big.dat");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(SMALL_FILE_LIMIT + 1)
        .unwrap();
    let zero = dir.join("zero");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    type Reader = (&'static str, fn(&Path) -> Result<(), String>);
    fn s<T, E: ToString>(r: Result<T, E>) -> Result<(), String> {
        r.map(|_| ()).map_err(|e| e.to_string())
    }
    let readers: [Reader; 13] = [
        ("OBJ", |p| s(emilion::geometry::read_obj(p))),
        ("OBJ surface", |p| s(emilion::geometry::read_obj_surface(p))),
        ("pattern JSON", |p| {
            s(emilion::garment::read_pattern_json(p))
        }),
        ("DXF", |p| s(emilion::garment::read_pattern_dxf(p))),
        ("garment table", |p| s(emilion::garment::read_garment(p))),
        ("fabric", |p| s(read_fabric(p))),
        ("Wang material", |p| s(emilion::kes::import_wang(p))),
        (".pts", |p| s(emilion::face::landmarks::read_pts(p))),
        ("rule file", |p| s(read_rules(p))),
        ("camera", |p| s(emilion::geometry::Camera::load(p))),
        ("PC2", |p| s(emilion::geometry::pc2::read_pc2(p))),
        ("pose CSV", |p| {
            s(emilion::face::sequence_files::read_pose_csv(p))
        }),
        ("joints CSV", |p| {
            s(emilion::tracking::sequence_files::read_joints_csv(p))
        }),
    ];
    for (name, read) in readers {
        for path in [&big, &zero] {
            let t = std::time::Instant::now();
            let e = read(path).expect_err(name);
            assert!(
                e.contains("max_file_bytes") && e.contains(&path.display().to_string()),
                "{name} on {}: {e}",
                path.display()
            );
            assert!(
                t.elapsed().as_secs_f64() < 10.0,
                "{name}: {:?}",
                t.elapsed()
            );
        }
    }
    // photos: the file size first, then the header
    let e = emilion::geometry::image::read_photo(&big)
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_file_bytes"), "{e}");
    let e = emilion::geometry::image::read_photo(&zero)
        .unwrap_err()
        .to_string();
    assert!(e.contains("zero") && e.contains("decoded"), "{e}");
}
