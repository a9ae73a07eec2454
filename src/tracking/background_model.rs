//! The background model of each camera of a sequence (its clean plates, or the per-pixel
//! median of frames spread over it) and the pixels where the scene ever changes, shared by
//! the body and club trackers.

use image::RgbImage;

use super::cost::Robust;
use super::pyramid::{median_background, Level};
use super::sequence_files::Sequence;
use super::tracker::TrackError;

/// Up to `count` frame indices spread evenly over `frames` frames (all of them when fewer).
fn spread_frames(frames: usize, count: usize) -> Vec<usize> {
    if frames <= count.max(1) {
        (0..frames).collect()
    } else {
        (0..count)
            .map(|i| i * (frames - 1) / (count - 1).max(1))
            .collect()
    }
}

/// Pixels of each camera where the scene changes at some time: the image differs from the
/// background (after its lighting gain) by more than `threshold` in robust distance in at
/// least one of up to `count` frames spread over the sequence. The others are a static
/// occluder or background the person never crosses (see
/// [`ViewLevel::active`](super::cost::ViewLevel::active)).
pub fn changing_pixels(
    seq: &Sequence,
    backgrounds: &[Level],
    count: usize,
    robust: Robust,
    threshold: f32,
) -> Result<Vec<Vec<bool>>, TrackError> {
    let picks = spread_frames(seq.frames, count);
    let mut masks: Vec<Vec<bool>> = backgrounds
        .iter()
        .map(|b| vec![false; b.rgb.len()])
        .collect();
    let mut scratch = Vec::new();
    for &k in &picks {
        for (c, img) in seq.frame_images(k)?.iter().enumerate() {
            let level = Level::from_image(img);
            let gain = super::pyramid::lighting_gain(&level, &backgrounds[c], &mut scratch)
                .clamp(0.2, 5.0);
            for ((m, p), b) in masks[c].iter_mut().zip(&level.rgb).zip(&backgrounds[c].rgb) {
                let q = p.map(|v| v / gain);
                if robust.rho_colours(&q, b) > threshold {
                    *m = true;
                }
            }
        }
    }
    Ok(masks)
}

/// The background model of each camera of `seq`: its clean plates when the sequence has them,
/// else the per-pixel median of `count` frames spread over it ([`sequence_backgrounds`]).
pub fn background_models(seq: &Sequence, count: usize) -> Result<Vec<Level>, TrackError> {
    Ok(match seq.background_plates()? {
        Some(plates) => plates.iter().map(Level::from_image).collect(),
        None => sequence_backgrounds(seq, seq.frames, count)?,
    })
}

/// Background model of every camera: the median of up to `count` frames spread evenly
/// over the sequence.
pub fn sequence_backgrounds(
    seq: &Sequence,
    frames: usize,
    count: usize,
) -> Result<Vec<Level>, TrackError> {
    let picks = spread_frames(frames, count);
    let mut per_camera: Vec<Vec<RgbImage>> = vec![Vec::new(); seq.cameras.len()];
    for &k in &picks {
        for (c, img) in seq.frame_images(k)?.into_iter().enumerate() {
            per_camera[c].push(img);
        }
    }
    Ok(per_camera
        .iter()
        .map(|imgs| median_background(&imgs.iter().collect::<Vec<_>>()))
        .collect())
}
