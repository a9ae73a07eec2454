//! C3D reading: the GEARS driver swing against the CSV another tool (the Python `c3d` package)
//! read from it, and malformed files written here byte by byte, each refused with an error
//! naming the file and what is wrong.

use emilion::body::markers::parse_c3d;
use emilion::body::read_c3d;
use emilion::geometry::export_frame::UpAxis;
use emilion::geometry::files::data_dir;

/// A tiny Intel C3D file, float format, in millimetres: `frames` frames of two points `A`, `B`
/// plus `analog` analog samples per frame, `A` invalid (residual −1) in frame 2.
fn tiny_c3d(frames: u16, analog: u16, coords: impl Fn(usize, usize) -> [f32; 3]) -> Vec<u8> {
    let mut b = vec![0u8; 512 * 2];
    b[0] = 2;
    b[1] = 0x50;
    let w =
        |b: &mut Vec<u8>, i: usize, v: u16| b[2 * i..2 * i + 2].copy_from_slice(&v.to_le_bytes());
    let f =
        |b: &mut Vec<u8>, i: usize, v: f32| b[2 * i..2 * i + 4].copy_from_slice(&v.to_le_bytes());
    w(&mut b, 1, 2);
    w(&mut b, 2, analog);
    w(&mut b, 3, 1);
    w(&mut b, 4, frames);
    f(&mut b, 6, -0.1);
    w(&mut b, 8, 3);
    f(&mut b, 10, 100.0);
    // parameter section
    let p = 512;
    b[p + 2] = 1;
    b[p + 3] = 84;
    let mut rec = Vec::new();
    // group POINT, id 1
    rec.extend_from_slice(&[5, (-1i8) as u8]);
    rec.extend_from_slice(b"POINT");
    rec.extend_from_slice(&3i16.to_le_bytes());
    rec.push(0);
    let param = |rec: &mut Vec<u8>, name: &[u8], kind: i8, dims: &[u8], data: &[u8]| {
        rec.push(name.len() as u8);
        rec.push(1);
        rec.extend_from_slice(name);
        let len = 2 + 1 + 1 + dims.len() + data.len() + 1;
        rec.extend_from_slice(&(len as i16).to_le_bytes());
        rec.push(kind as u8);
        rec.push(dims.len() as u8);
        rec.extend_from_slice(dims);
        rec.extend_from_slice(data);
        rec.push(0);
    };
    param(&mut rec, b"USED", 2, &[], &2u16.to_le_bytes());
    param(&mut rec, b"UNITS", -1, &[2], b"mm");
    param(&mut rec, b"Y_SCREEN", -1, &[2], b"+Y");
    param(&mut rec, b"LABELS", -1, &[4, 2], b"A   B   ");
    rec.extend_from_slice(&[0, 0]);
    b[p + 4..p + 4 + rec.len()].copy_from_slice(&rec);
    for fr in 0..frames as usize {
        for m in 0..2 {
            let c = coords(fr, m);
            for v in c {
                b.extend_from_slice(&v.to_le_bytes());
            }
            let r: f32 = if fr == 1 && m == 0 { -1.0 } else { 3.0 };
            b.extend_from_slice(&r.to_le_bytes());
        }
        for a in 0..analog {
            b.extend_from_slice(&(a as f32).to_le_bytes());
        }
    }
    b
}

fn err(bytes: &[u8]) -> String {
    match parse_c3d(bytes, "bad.c3d") {
        Ok(_) => panic!("a malformed file was read"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_tiny_hand_written_file_reads_in_metres_with_its_invalid_sample_flagged() {
    let bytes = tiny_c3d(3, 4, |f, m| [f as f32 * 10.0, m as f32 * 1000.0, -5.0]);
    let t = parse_c3d(&bytes, "tiny.c3d").unwrap();
    assert_eq!(t.frames, 3);
    assert_eq!(t.labels, ["A", "B"]);
    assert_eq!(t.rate, 100.0);
    assert_eq!(t.up, UpAxis::Y);
    assert_eq!(t.invalid_count(), 1);
    assert!(t.position(1, 0).is_none());
    let b = t.position(2, 1).unwrap();
    assert!((b - emilion::geometry::Vec3::new(0.02, 1.0, -0.005)).norm() < 1e-9);
    // y up in the file: the engine's z is the file's y
    let w = t.world(2, 1).unwrap();
    assert!((w - emilion::geometry::Vec3::new(0.02, 0.005, 1.0)).norm() < 1e-9);
    // residual 3 in file units times |POINT:SCALE| 0.1, millimetres
    assert!((t.residual(0, 0) - 0.0003).abs() < 1e-10);
    // two markers are too few to tell the up axis from the data: +Z
    assert_eq!(t.infer_up(), UpAxis::Z);
}

#[test]
fn malformed_c3d_files_get_errors_naming_the_file_and_the_fault() {
    let good = tiny_c3d(3, 0, |f, m| [f as f32, m as f32, 1.0]);
    // shorter than a header
    let e = err(&good[..100]);
    assert!(
        e.contains("bad.c3d") && e.contains("512-byte header"),
        "{e}"
    );
    // not a C3D key
    let mut b = good.clone();
    b[1] = 0;
    assert!(err(&b).contains("expected 0x50"));
    // parameter block 0 (c3dio 0.8 panics here)
    let mut b = good.clone();
    b[0] = 0;
    assert!(err(&b).contains("parameter section starts at block 0"));
    // data block 1 (c3dio 0.8 panics here)
    let mut b = good.clone();
    b[16] = 1;
    assert!(err(&b).contains("data starts at block 1"));
    // unknown processor
    let mut b = good.clone();
    b[512 + 3] = 99;
    assert!(err(&b).contains("processor type 99"));
    // truncated in the data (c3dio 0.8 returns fewer frames without an error)
    let e = err(&good[..good.len() - 5]);
    assert!(e.contains("truncated") && e.contains("3 frames"), "{e}");
    // absurd frame count: 65535 frames announced, 3 present
    let mut b = good.clone();
    b[8] = 0xff;
    b[9] = 0xff;
    let e = err(&b);
    assert!(e.contains("truncated") && e.contains("65535 frames"), "{e}");
    // last frame before first
    let mut b = good.clone();
    b[6] = 9;
    assert!(err(&b).contains("before first frame"));
    // NaN scale and rate
    let mut b = good.clone();
    b[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(err(&b).contains("POINT:SCALE NaN"), "{}", err(&b));
    let mut b = good.clone();
    b[20..24].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(err(&b).contains("POINT:RATE NaN"));
    // NaN coordinate in a valid sample
    let nan = tiny_c3d(3, 0, |f, _| [if f == 2 { f32::NAN } else { 0.0 }, 0.0, 0.0]);
    let e = err(&nan);
    assert!(
        e.contains("frame 3") && e.contains("`A`") && e.contains("NaN"),
        "{e}"
    );
    // a parameter whose data runs past the section
    let mut b = good.clone();
    let at = b.windows(5).position(|w| w == b"UNITS").unwrap();
    b[at + 8] = 2; // two dimensions of 255: 65,025 characters
    b[at + 9] = 255;
    b[at + 10] = 255;
    let e = err(&b);
    assert!(e.contains("UNITS") && e.contains("runs past"), "{e}");
    // no panic on any truncation of the good file
    for n in 0..good.len() {
        let _ = parse_c3d(&good[..n], "cut.c3d");
    }
}

fn driver() -> Option<std::path::PathBuf> {
    let p = data_dir().join("motion/golf/C3D_TA_Driver.c3d");
    if p.is_file() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

#[test]
fn the_driver_swing_matches_the_csv_read_by_another_tool() {
    let Some(path) = driver() else { return };
    let t = read_c3d(&path).unwrap();
    assert_eq!(t.frames, 654);
    assert_eq!(t.rate, 360.0);
    assert_eq!(t.markers(), 38);
    // GEARS declares POINT:Y_SCREEN = +Z, but its data are y up (the head is highest in y)
    assert_eq!(t.up, UpAxis::Z);
    assert_eq!(t.infer_up(), UpAxis::Y);
    assert_eq!(t.invalid_count(), 717);
    let csv = std::fs::read_to_string(path.with_extension("csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().trim_end().split(',').collect();
    assert_eq!(header.len(), 2 + 3 * 38);
    for (m, label) in t.labels.iter().enumerate() {
        assert_eq!(header[2 + 3 * m], format!("{label}_x"));
    }
    let (mut rows, mut empty, mut worst) = (0, 0, 0.0f64);
    for (f, line) in lines.enumerate() {
        let cells: Vec<&str> = line.trim_end().split(',').collect();
        assert_eq!(cells[0].parse::<usize>().unwrap(), f + 1);
        let time: f64 = cells[1].parse().unwrap();
        assert!((time - f as f64 / 360.0).abs() < 1e-6);
        for m in 0..38 {
            let c = &cells[2 + 3 * m..5 + 3 * m];
            match t.position(f, m) {
                None => {
                    assert!(c.iter().all(|s| s.is_empty()), "frame {f} marker {m}");
                    empty += 1;
                }
                Some(p) => {
                    for k in 0..3 {
                        let v: f64 = c[k].parse().unwrap();
                        worst = worst.max((v - p[k]).abs());
                    }
                }
            }
        }
        rows += 1;
    }
    assert_eq!(rows, 654);
    assert_eq!(empty, 717);
    assert!(worst <= 1e-6, "largest difference from the CSV {worst} m");
}
