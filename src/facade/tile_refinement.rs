//! Tile refinement (Müller et al. 2007 §3, `facade-reconstruction.md` §1): what stands round
//! a window and below it — the frame (casing) and the sill — found with the edge-based
//! split-line measure and synchronised across the windows it is given. A split line's
//! strength is the mean grey step across it; for each distance `d` outside the window's
//! sides (left, right, top) the strengths of all those windows are averaged, and the frame's
//! outer edge is the strongest line standing clearly out of that profile. The sill is found
//! the same way below the window (and below the frame). Averaging over the windows is
//! Müller's synchronisation: a tree or a shadow on one window does not move the split. The
//! grammar of windows found one by one measures each size of window on its own (local
//! synchronisation, [`super::window_grammar::grammar_of_windows`]); the layout's window is
//! measured over all its cells. The result is a [`Refinement`], which
//! [`framed_window`](super::refinement::framed_window) writes as rules.

use super::rect::Rect;
use super::refinement::Refinement;
use crate::geometry::image::Gray;

/// How much stronger than the median of its profile a split line must be to be a frame's or
/// a sill's edge.
pub const PEAK: f64 = 2.5;
/// Widest frame, as a share of the windows' median smaller side.
pub const MAX_FRAME: f64 = 0.2;
/// Tallest sill, as a share of the windows' median height.
pub const MAX_SILL: f64 = 0.35;
/// Fewest windows to measure on: one or two windows do not average anything out.
pub const MIN_WINDOWS: usize = 3;

/// Mean grey step across the vertical line between columns `c − 1` and `c` over rows
/// `[y0, y1)`, or across the horizontal line between rows `c − 1` and `c` over columns
/// `[y0, y1)` (`horizontal`). `None` where the line leaves the image.
fn line_strength(img: &Gray, horizontal: bool, c: i64, (a, b): (u32, u32)) -> Option<f64> {
    let (w, h) = (img.width as i64, img.height as i64);
    let across = if horizontal { h } else { w };
    if c < 1 || c >= across || b <= a {
        return None;
    }
    let along = if horizontal { img.width } else { img.height };
    let b = b.min(along);
    if b <= a {
        return None;
    }
    let c = c as u32;
    let sum: f64 = (a..b)
        .map(|t| {
            let (p, q) = if horizontal {
                (img.at(t, c), img.at(t, c - 1))
            } else {
                (img.at(c, t), img.at(c - 1, t))
            };
            (p as f64 - q as f64).abs()
        })
        .sum();
    Some(sum / (b - a) as f64)
}

/// The mean over windows of `strength(window, d)` for d = 1..=n (entries where no window's
/// line lies inside the image are 0).
fn profile(windows: &[Rect], n: u32, strength: impl Fn(&Rect, u32) -> Vec<f64>) -> Vec<f64> {
    (1..=n)
        .map(|d| {
            let (sum, count) = windows
                .iter()
                .flat_map(|r| strength(r, d))
                .fold((0.0, 0usize), |(s, k), v| (s + v, k + 1));
            if count > 0 {
                sum / count as f64
            } else {
                0.0
            }
        })
        .collect()
}

/// The distance (1-based index into `p`) of the strongest local maximum at 2 or more that
/// is [`PEAK`] times the median of `p` or more; 0 when none is.
fn peak(p: &[f64]) -> u32 {
    let mut sorted = p.to_vec();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else {
        return 0;
    };
    let mut best = (0, 0.0);
    for i in 1..p.len() {
        let local = p[i] > p[i - 1] && p.get(i + 1).is_none_or(|&q| p[i] >= q);
        if local && p[i] >= PEAK * median && p[i] > best.1 {
            best = (i as u32 + 1, p[i]);
        }
    }
    best.0
}

/// The median of `v` (0 for none).
fn median(mut v: Vec<u32>) -> u32 {
    v.sort_unstable();
    v.get(v.len() / 2).copied().unwrap_or(0)
}

/// Measures where the sides of `windows` (pixels of `img`) lie (with `snap`; else they stay
/// where they are), then the frame and the sill round them, synchronised across them all;
/// nothing with fewer than [`MIN_WINDOWS`].
///
/// Snapping is for windows placed by the layout (the irreducible tile's band, which its
/// blurred profiles draw in by a few pixels). Windows found one by one already have their
/// outline where their contrast is: on the tuning half, snapping them within 1, 2, 3 or 5 px
/// only lowered the window IoU (0.287 → 0.286, 0.285, 0.285, 0.282) and never raised F1.
pub fn measure(img: &Gray, windows: &[Rect], snap: bool) -> Refinement {
    if windows.len() < MIN_WINDOWS {
        return Refinement::default();
    }
    let side = median(
        windows
            .iter()
            .map(|r| (r.x1 - r.x0).min(r.y1 - r.y0))
            .collect(),
    );
    let height = median(windows.iter().map(|r| r.y1 - r.y0).collect());
    // the profiles reach twice as far as a frame or a sill may: their medians are the wall's
    let max_frame = (MAX_FRAME * side as f64).round() as u32;
    let max_sill = (MAX_SILL * height as f64).round() as u32;
    if max_frame < 2 && max_sill < 2 {
        return Refinement::default();
    }
    // each side moves to its strongest line within a frame's width (in by a quarter of the
    // window at most), the same move for every window
    let (reach_in, reach_out) = if snap {
        (max_frame.min(side / 4) as i64, max_frame as i64)
    } else {
        (0, 0)
    };
    let mut sides = [0i32; 4];
    for (k, out) in sides.iter_mut().enumerate() {
        let mut best = (0i64, f64::NEG_INFINITY);
        for o in -reach_in..=reach_out {
            let (sum, n) = windows
                .iter()
                .filter_map(|r| match k {
                    0 => line_strength(img, false, r.x0 as i64 - o, (r.y0, r.y1)),
                    1 => line_strength(img, true, r.y0 as i64 - o, (r.x0, r.x1)),
                    2 => line_strength(img, false, r.x1 as i64 + o, (r.y0, r.y1)),
                    _ => line_strength(img, true, r.y1 as i64 + o, (r.x0, r.x1)),
                })
                .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
            let mean = if n > 0 { sum / n as f64 } else { 0.0 };
            // ties go to the smaller move
            if mean > best.1 || (mean == best.1 && o.abs() < best.0.abs()) {
                best = (o, mean);
            }
        }
        *out = best.0 as i32;
    }
    let bare = Refinement {
        sides,
        ..Default::default()
    };
    let windows: Vec<Rect> = windows.iter().map(|r| bare.window(r)).collect();
    let windows = &windows[..];
    let frame_profile = profile(windows, 2 * max_frame, |r, d| {
        let (x0, x1, y0) = (r.x0 as i64, r.x1 as i64, r.y0 as i64);
        let d = d as i64;
        [
            line_strength(img, false, x0 - d, (r.y0, r.y1)),
            line_strength(img, false, x1 + d, (r.y0, r.y1)),
            line_strength(img, true, y0 - d, (r.x0, r.x1)),
        ]
        .into_iter()
        .flatten()
        .collect()
    });
    let frame = peak(&frame_profile).min(max_frame);
    let sill_profile = profile(windows, 2 * max_sill, |r, s| {
        let c = (r.y1 + frame + s) as i64;
        let span = (r.x0.saturating_sub(frame), r.x1 + frame);
        line_strength(img, true, c, span).into_iter().collect()
    });
    let sill = peak(&sill_profile);
    Refinement {
        sides,
        frame,
        sill: if sill <= max_sill { sill } else { 0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facade::rasterize::rasterize;

    /// A wall (grey 150, noise ±10) with a row of dark windows (40) in frames of `frame` px
    /// (grey 220) over sills of `sill` px (230, then a shadow row of 90 below).
    fn wall_with_windows(frame: u32, sill: u32) -> (Gray, Vec<Rect>) {
        let windows: Vec<Rect> = (0..5)
            .map(|j| Rect::new(15 + 50 * j, 20, 35 + 50 * j, 55))
            .collect();
        let img = painted_wall(260, 90, &[(&windows, frame, sill)]);
        (img, windows)
    }

    /// A `w` × `h` wall painted as in [`wall_with_windows`] with each group of windows in its
    /// own frame and over its own sill.
    fn painted_wall(w: u32, h: u32, groups: &[(&[Rect], u32, u32)]) -> Gray {
        Gray::painted(w, h, 11, 20.0, |x, y| {
            let inside = |r: &Rect| (r.x0..r.x1).contains(&x) && (r.y0..r.y1).contains(&y);
            let mut shade = 150.0;
            for &(windows, frame, sill) in groups {
                let r = Refinement {
                    sides: [0; 4],
                    frame,
                    sill,
                };
                let within = |k: Refinement| windows.iter().any(|q| inside(&k.unit(q)));
                if windows.iter().any(inside) {
                    return 40.0;
                } else if within(Refinement { sill: 0, ..r }) {
                    return 220.0;
                } else if within(r) {
                    return 230.0;
                } else if sill > 0
                    && within(Refinement {
                        sill: sill + 1,
                        ..r
                    })
                {
                    shade = 90.0;
                }
            }
            shade
        })
    }

    #[test]
    fn frames_and_sills_are_measured_to_the_pixel() {
        for (frame, sill) in [(2, 4), (3, 0), (0, 5), (0, 0)] {
            let (img, windows) = wall_with_windows(frame, sill);
            let got = measure(&img, &windows, true);
            assert_eq!((got.frame, got.sill), (frame, sill));
            assert_eq!(got.sides, [0; 4], "the windows were given where they are");
            // windows found a pixel or two too small come back to their edges
            let small: Vec<Rect> = windows
                .iter()
                .map(|r| Rect::new(r.x0 + 2, r.y0 + 1, r.x1 - 1, r.y1 - 2))
                .collect();
            let got = measure(&img, &small, true);
            assert_eq!(measure(&img, &small, false).sides, [0; 4]);
            assert_eq!(got.sides, [2, 1, 1, 2], "{frame} {sill}");
            assert_eq!((got.frame, got.sill), (frame, sill));
            let back: Vec<Rect> = small.iter().map(|r| got.window(r)).collect();
            assert_eq!(back, windows);
        }
        // two windows are too few to synchronise anything
        let (img, windows) = wall_with_windows(2, 4);
        assert!(measure(&img, &windows[..2], true).is_none());
    }

    #[test]
    fn each_size_of_window_gets_its_own_frame_and_sill() {
        // an upper row of tall framed windows over 3 px sills, a lower row of wide bare
        // windows over 6 px sills: synchronised size by size (local synchronisation), each
        // row gets its own
        let upper: Vec<Rect> = (0..5)
            .map(|j| Rect::new(15 + 50 * j, 15, 35 + 50 * j, 50))
            .collect();
        let lower: Vec<Rect> = (0..5)
            .map(|j| Rect::new(10 + 50 * j, 80, 40 + 50 * j, 100))
            .collect();
        let img = painted_wall(260, 125, &[(&upper, 2, 3), (&lower, 0, 6)]);
        let windows: Vec<Rect> = upper.iter().chain(&lower).copied().collect();
        let g = crate::facade::window_grammar::grammar_of_windows(&windows, 260, 125, &|ws| {
            measure(&img, ws, false)
        });
        let leaves = g.derive(260.0, 125.0).expect("derives");
        let names = g.elements();
        let of = |name: &str| {
            let k = names.iter().position(|n| n == name);
            leaves.iter().filter(move |l| l.element == k && k.is_some())
        };
        // four strips of frame round each upper window, none round the lower ones
        assert_eq!(of("wall_frame").count(), 20, "{}", g.to_text());
        assert!(of("wall_frame").all(|l| l.scope.y1 <= 60.0));
        // a sill under every window, as tall as it was painted
        let sills: Vec<(f64, f64)> = of("wall_sill")
            .map(|l| (l.scope.y0, l.scope.y1 - l.scope.y0))
            .collect();
        assert_eq!(sills.len(), 10, "{}", g.to_text());
        for (y0, height) in sills {
            let want = if y0 < 60.0 { (52.0, 3.0) } else { (100.0, 6.0) };
            assert_eq!((y0, height), want, "{}", g.to_text());
        }
        // all ten synchronised together, the one frame and sill are right for neither row
        let all = measure(&img, &windows, false);
        assert!(
            (all.frame, all.sill) != (2, 3) && (all.frame, all.sill) != (0, 6),
            "{all:?}"
        );
        // and the parse paints the windows where they are
        assert_eq!(rasterize(&leaves, 260, 125).windows.len(), 10);
    }
}
