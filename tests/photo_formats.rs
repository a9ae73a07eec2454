//! Every photo format the engine lists ([`PHOTO_EXTENSIONS`]) is read wherever a photo is read:
//! a known synthetic picture written as PPM, PGM, TIFF, BMP and TGA byte by byte here (from
//! the formats' specifications, not by the `image` crate the engine decodes with) and as WebP
//! by the `image` crate's lossless encoder, read back pixel for pixel by `read_photo`, listed
//! by `photo_files`, and taken as face photos with their `.pts` landmarks; a file that is not
//! an image gives one clear error naming it.

use std::path::{Path, PathBuf};

use emilion::face::fit_run::load_photos;
use emilion::geometry::image::{photo_files, photo_with_stem, read_photo, PHOTO_EXTENSIONS};

const W: u32 = 512;
const H: u32 = 512;

fn temp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("photo_formats")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The known picture: every channel a different function of (x, y).
fn rgb(x: u32, y: u32) -> [u8; 3] {
    [
        ((x * 7 + y) % 256) as u8,
        ((y * 3 + x / 5) % 256) as u8,
        ((x ^ y) % 256) as u8,
    ]
}

/// Grey level of the grey picture.
fn grey(x: u32, y: u32) -> u8 {
    ((x + 2 * y) % 256) as u8
}

fn ppm() -> Vec<u8> {
    let mut b = format!("P6\n# written by hand\n{W} {H}\n255\n").into_bytes();
    for y in 0..H {
        for x in 0..W {
            b.extend(rgb(x, y));
        }
    }
    b
}

fn pgm() -> Vec<u8> {
    let mut b = format!("P5 {W} {H} 255\n").into_bytes();
    for y in 0..H {
        for x in 0..W {
            b.push(grey(x, y));
        }
    }
    b
}

/// Baseline TIFF 6.0, little-endian, one uncompressed strip of 8-bit RGB.
fn tiff() -> Vec<u8> {
    let entries: [(u16, u16, u32, u32); 9] = [
        (256, 4, 1, W),         // ImageWidth, LONG
        (257, 4, 1, H),         // ImageLength
        (258, 3, 3, 122),       // BitsPerSample: 3 SHORTs at offset 122
        (259, 3, 1, 1),         // Compression: none
        (262, 3, 1, 2),         // PhotometricInterpretation: RGB
        (273, 4, 1, 128),       // StripOffsets
        (277, 3, 1, 3),         // SamplesPerPixel
        (278, 4, 1, H),         // RowsPerStrip
        (279, 4, 1, W * H * 3), // StripByteCounts
    ];
    let mut b = b"II*\0".to_vec();
    b.extend(8u32.to_le_bytes());
    b.extend((entries.len() as u16).to_le_bytes());
    for (tag, kind, count, value) in entries {
        b.extend(tag.to_le_bytes());
        b.extend(kind.to_le_bytes());
        b.extend(count.to_le_bytes());
        if kind == 3 && count == 1 {
            b.extend((value as u16).to_le_bytes());
            b.extend([0, 0]);
        } else {
            b.extend(value.to_le_bytes());
        }
    }
    b.extend(0u32.to_le_bytes()); // no next IFD
    assert_eq!(b.len(), 122);
    for _ in 0..3 {
        b.extend(8u16.to_le_bytes());
    }
    assert_eq!(b.len(), 128);
    for y in 0..H {
        for x in 0..W {
            b.extend(rgb(x, y));
        }
    }
    b
}

/// Windows BMP, BITMAPINFOHEADER, 24-bit BGR rows bottom-up padded to 4 bytes.
fn bmp() -> Vec<u8> {
    let row = (W * 3).div_ceil(4) * 4;
    let size = 54 + row * H;
    let mut b = b"BM".to_vec();
    for v in [size, 0, 54, 40, W, H] {
        b.extend(v.to_le_bytes());
    }
    b.extend(1u16.to_le_bytes());
    b.extend(24u16.to_le_bytes());
    for v in [0u32, row * H, 2835, 2835, 0, 0] {
        b.extend(v.to_le_bytes());
    }
    for y in (0..H).rev() {
        let start = b.len();
        for x in 0..W {
            let [r, g, bl] = rgb(x, y);
            b.extend([bl, g, r]);
        }
        b.resize(start + row as usize, 0);
    }
    b
}

/// Truevision TGA, uncompressed true-colour, 24-bit BGR, rows top-down (descriptor bit 5).
fn tga() -> Vec<u8> {
    let mut b = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    b.extend((W as u16).to_le_bytes());
    b.extend((H as u16).to_le_bytes());
    b.extend([24, 0x20]);
    for y in 0..H {
        for x in 0..W {
            let [r, g, bl] = rgb(x, y);
            b.extend([bl, g, r]);
        }
    }
    b
}

/// Lossless WebP by the `image` crate's encoder (no hand-written WebP: its lossless
/// bitstream is entropy-coded).
fn webp() -> Vec<u8> {
    let img = image::RgbImage::from_fn(W, H, |x, y| image::Rgb(rgb(x, y)));
    let mut b = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut b)
        .encode(img.as_raw(), W, H, image::ExtendedColorType::Rgb8)
        .unwrap();
    b
}

/// (extension, bytes, whether the picture is the grey one).
fn files() -> Vec<(&'static str, Vec<u8>, bool)> {
    vec![
        ("ppm", ppm(), false),
        ("pgm", pgm(), true),
        ("tif", tiff(), false),
        ("bmp", bmp(), false),
        ("webp", webp(), false),
        ("TGA", tga(), false),
    ]
}

fn check_pixels(img: &image::RgbImage, is_grey: bool, what: &str) {
    assert_eq!(img.dimensions(), (W, H), "{what}");
    for (x, y, p) in img.enumerate_pixels() {
        let want = if is_grey { [grey(x, y); 3] } else { rgb(x, y) };
        assert_eq!(p.0, want, "{what}: pixel ({x}, {y})");
    }
}

#[test]
fn each_format_reads_back_the_known_picture() {
    let d = temp("read");
    for (ext, bytes, is_grey) in files() {
        assert!(
            PHOTO_EXTENSIONS.contains(&ext.to_ascii_lowercase().as_str()),
            "{ext}"
        );
        let path = d.join(format!("picture_{ext}.{ext}"));
        std::fs::write(&path, bytes).unwrap();
        check_pixels(&read_photo(&path).unwrap(), is_grey, ext);
    }
    // all listed, the `.pts` and text files beside them not
    std::fs::write(d.join("notes.txt"), "x").unwrap();
    let listed = photo_files(&d).unwrap();
    assert_eq!(listed.len(), files().len(), "{listed:?}");
    // a frame found by its stem whatever its format
    assert_eq!(
        photo_with_stem(&d, "picture_webp"),
        Some(d.join("picture_webp.webp"))
    );
    assert_eq!(
        photo_with_stem(&d, "picture_TGA"),
        Some(d.join("picture_TGA.TGA"))
    );
    assert_eq!(photo_with_stem(&d, "notes"), None);
}

#[test]
fn face_photos_in_every_format_are_read_with_their_landmarks() {
    let pts = std::fs::read_to_string("tests/data/faces/astronaut.pts").unwrap();
    for (ext, bytes, is_grey) in files() {
        let d = temp(&format!("face_{ext}"));
        std::fs::write(d.join(format!("person.{ext}")), bytes).unwrap();
        std::fs::write(d.join("person.pts"), &pts).unwrap();
        let set = load_photos(&d, None).unwrap_or_else(|e| panic!("{ext}: {e}"));
        assert_eq!(set.names, ["person"], "{ext}");
        assert_eq!(set.views[0].landmarks.len(), 68, "{ext}");
        check_pixels(&set.images[0], is_grey, ext);
    }
}

#[test]
fn a_file_that_is_not_an_image_is_named_in_a_clear_error() {
    let d = temp("bad");
    let cases = [
        ("garbage.ppm", b"this is not a picture at all".to_vec()),
        ("truncated.bmp", bmp()[..200].to_vec()),
        ("text.webp", b"RIFF\x04\0\0\0WEBPnope".to_vec()),
        ("empty.tif", Vec::new()),
    ];
    for (name, bytes) in &cases {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = read_photo(&path).unwrap_err().to_string();
        println!("{e}");
        assert!(
            e.contains(name) && e.contains("cannot be decoded as an image") && e.contains("webp"),
            "{e}"
        );
    }
    // the same error through the face photos
    let f = temp("bad_face");
    std::fs::write(f.join("person.ppm"), b"P6 not really").unwrap();
    std::fs::copy("tests/data/faces/astronaut.pts", f.join("person.pts")).unwrap();
    let e = load_photos(&f, None).unwrap_err().to_string();
    assert!(
        e.contains("person.ppm") && e.contains("cannot be decoded as an image"),
        "{e}"
    );
    // a missing file names it too
    let e = read_photo(&d.join("absent.png")).unwrap_err().to_string();
    assert!(e.contains("absent.png"), "{e}");
}
