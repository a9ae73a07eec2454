//! Animated PNG (APNG) files, which every current browser plays: [`AnimatedPng`] streams RGB
//! frames of one size into a file at a fixed frame rate, looping, without holding the frames
//! in memory. A viewer without APNG support shows the first frame.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use image::RgbImage;

/// An error writing an animated PNG, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct AnimatedPngError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub message: String,
}

/// An animated PNG being written.
pub struct AnimatedPng {
    path: PathBuf,
    writer: png::Writer<BufWriter<File>>,
    width: u32,
    height: u32,
    frames: u32,
    written: u32,
}

impl std::fmt::Debug for AnimatedPng {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnimatedPng")
            .field("path", &self.path)
            .field("frames", &self.frames)
            .field("written", &self.written)
            .finish_non_exhaustive()
    }
}

impl AnimatedPng {
    /// Starts `path`: `frames` frames (at least 1) of `width` × `height` pixels shown at
    /// `fps` frames per second (0.1 to 1000), looping for ever.
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        frames: u32,
        fps: f64,
    ) -> Result<AnimatedPng, AnimatedPngError> {
        let fail = |m: String| AnimatedPngError {
            path: path.to_path_buf(),
            message: m,
        };
        if width == 0 || height == 0 || frames == 0 {
            return Err(fail(format!(
                "an animation needs frames of some size, got {frames} frames of {width}×{height}"
            )));
        }
        if !(fps.is_finite() && (0.1..=1000.0).contains(&fps)) {
            return Err(fail(format!(
                "frame rate must be in [0.1, 1000], got {fps}"
            )));
        }
        let file = File::create(path).map_err(|e| fail(e.to_string()))?;
        let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_animated(frames, 0)
            .map_err(|e| fail(e.to_string()))?;
        // the delay as a fraction: 1000 / (fps · 1000), both within u16
        let den = (fps * 100.0).round().clamp(1.0, 65_535.0) as u16;
        enc.set_frame_delay(100, den)
            .map_err(|e| fail(e.to_string()))?;
        let writer = enc.write_header().map_err(|e| fail(e.to_string()))?;
        Ok(AnimatedPng {
            path: path.to_path_buf(),
            writer,
            width,
            height,
            frames,
            written: 0,
        })
    }

    /// Appends a frame; an error for a frame of another size or one past the count given.
    pub fn add(&mut self, frame: &RgbImage) -> Result<(), AnimatedPngError> {
        let fail = |m: String| AnimatedPngError {
            path: self.path.clone(),
            message: m,
        };
        if frame.dimensions() != (self.width, self.height) {
            return Err(fail(format!(
                "frame {} is {}×{}, the animation {}×{}",
                self.written,
                frame.width(),
                frame.height(),
                self.width,
                self.height
            )));
        }
        if self.written == self.frames {
            return Err(fail(format!(
                "more than the {} frames announced",
                self.frames
            )));
        }
        self.writer
            .write_image_data(frame.as_raw())
            .map_err(|e| fail(e.to_string()))?;
        self.written += 1;
        Ok(())
    }

    /// Closes the file; an error when fewer frames were added than announced.
    pub fn finish(self) -> Result<PathBuf, AnimatedPngError> {
        let path = self.path;
        if self.written != self.frames {
            return Err(AnimatedPngError {
                message: format!("{} of {} frames written", self.written, self.frames),
                path,
            });
        }
        self.writer.finish().map_err(|e| AnimatedPngError {
            path: path.clone(),
            message: e.to_string(),
        })?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_animation_decodes_with_its_frames_and_rate() {
        let dir = std::env::temp_dir().join("emilion_apng_test");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.png");
        let mut a = AnimatedPng::create(&path, 4, 3, 3, 10.0).unwrap();
        for k in 0..3u8 {
            a.add(&RgbImage::from_pixel(4, 3, image::Rgb([k * 100, 0, 0])))
                .unwrap();
        }
        assert!(a.add(&RgbImage::new(4, 3)).is_err());
        a.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let info = dec.info();
        let actl = info.animation_control.unwrap();
        assert_eq!((actl.num_frames, actl.num_plays), (3, 0));
        let fctl = info.frame_control.unwrap();
        assert_eq!(fctl.delay_num as f64 / fctl.delay_den as f64, 0.1);
        let mut buf = vec![0; dec.output_buffer_size().unwrap()];
        let mut reds = Vec::new();
        for _ in 0..3 {
            dec.next_frame(&mut buf).unwrap();
            reds.push(buf[0]);
        }
        assert_eq!(reds, vec![0, 100, 200]);
        let bad = AnimatedPng::create(&dir.join("b.png"), 4, 3, 1, f64::NAN);
        assert!(bad.unwrap_err().to_string().contains("frame rate"));
    }
}
