//! Scores of a facade parse against a labelled photo (`facade-reconstruction.md` §4.2): a
//! pixel confusion matrix over the scored classes (ignored pixels left out), from which pixel
//! accuracy and per-class IoU (window IoU is the headline figure); and window detection:
//! predicted window rectangles matched one-to-one to ground-truth windows by the Hungarian
//! method on IoU, a match counting when its IoU is 0.5 or more.

use serde::Serialize;

use super::assignment::min_cost_assignment;
use super::error::FacadeError;
use super::instances::{window_instances, Instance};
use super::labels::{Class, LabelMap};
use super::rect::Rect;

/// IoU a matched window needs to count as found.
pub const MATCH_IOU: f64 = 0.5;

/// Pixel counts by (ground truth, prediction) over the scored classes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PixelScore {
    /// `confusion[truth][predicted]`, classes in [`Class::SCORED`] order.
    pub confusion: [[u64; 5]; 5],
}

impl PixelScore {
    /// Counts `pred` against `truth`, pixels ignored in either left out.
    pub fn of(pred: &LabelMap, truth: &LabelMap) -> Result<Self, FacadeError> {
        same_size(pred, truth)?;
        let mut s = PixelScore::default();
        for (p, t) in pred.classes.iter().zip(&truth.classes) {
            if let (Some(i), Some(j)) = (t.index(), p.index()) {
                s.confusion[i][j] += 1;
            }
        }
        Ok(s)
    }

    /// Adds another image's counts (pooled scores).
    pub fn add(&mut self, o: &PixelScore) {
        for i in 0..5 {
            for j in 0..5 {
                self.confusion[i][j] += o.confusion[i][j];
            }
        }
    }

    /// Share of scored pixels labelled right.
    pub fn accuracy(&self) -> f64 {
        let total: u64 = self.confusion.iter().flatten().sum();
        let right: u64 = (0..5).map(|i| self.confusion[i][i]).sum();
        ratio(right, total)
    }

    /// Intersection over union of `class` (0 when neither truth nor prediction has it).
    pub fn iou(&self, class: Class) -> f64 {
        let Some(k) = class.index() else { return 0.0 };
        let tp = self.confusion[k][k];
        let truth: u64 = self.confusion[k].iter().sum();
        let pred: u64 = (0..5).map(|i| self.confusion[i][k]).sum();
        ratio(tp, truth + pred - tp)
    }
}

/// Window detection counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct DetectionScore {
    /// Ground-truth windows found (IoU ≥ 0.5).
    pub true_positives: u64,
    /// Predicted windows that found none.
    pub false_positives: u64,
    /// Ground-truth windows not found.
    pub false_negatives: u64,
    /// Sum of the IoUs of the true positives.
    pub iou_sum: f64,
}

impl DetectionScore {
    /// Matches `pred` to `truth`: a prediction matched to a don't-care window counts for
    /// nothing; a don't-care window left unmatched is no miss.
    pub fn of(pred: &[Rect], truth: &[Instance]) -> Self {
        let (n, m) = (pred.len(), truth.len());
        let cost: Vec<f64> = pred
            .iter()
            .flat_map(|p| truth.iter().map(move |t| 1.0 - p.iou(&t.rect)))
            .collect();
        let assigned = min_cost_assignment(&cost, n, m);
        let mut s = DetectionScore::default();
        let mut found = vec![false; m];
        for (i, a) in assigned.iter().enumerate() {
            match a {
                Some(j) if pred[i].iou(&truth[*j].rect) >= MATCH_IOU => {
                    found[*j] = true;
                    if !truth[*j].dont_care {
                        s.true_positives += 1;
                        s.iou_sum += pred[i].iou(&truth[*j].rect);
                    }
                }
                _ => s.false_positives += 1,
            }
        }
        s.false_negatives = truth
            .iter()
            .zip(&found)
            .filter(|(t, f)| !t.dont_care && !**f)
            .count() as u64;
        s
    }

    /// Adds another image's counts.
    pub fn add(&mut self, o: &DetectionScore) {
        self.true_positives += o.true_positives;
        self.false_positives += o.false_positives;
        self.false_negatives += o.false_negatives;
        self.iou_sum += o.iou_sum;
    }

    /// Found over predicted (1 when nothing was predicted).
    pub fn precision(&self) -> f64 {
        if self.true_positives + self.false_positives == 0 {
            return 1.0;
        }
        ratio(
            self.true_positives,
            self.true_positives + self.false_positives,
        )
    }

    /// Found over present (1 when nothing was there).
    pub fn recall(&self) -> f64 {
        if self.true_positives + self.false_negatives == 0 {
            return 1.0;
        }
        ratio(
            self.true_positives,
            self.true_positives + self.false_negatives,
        )
    }

    /// F1 at IoU 0.5: 2 TP / (2 TP + FP + FN); 1 when there was nothing to find and nothing
    /// was predicted.
    pub fn f1(&self) -> f64 {
        let d = 2 * self.true_positives + self.false_positives + self.false_negatives;
        if d == 0 {
            1.0
        } else {
            ratio(2 * self.true_positives, d)
        }
    }
}

/// Both scores of one parse.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct FacadeScore {
    /// Pixel counts.
    pub pixels: PixelScore,
    /// Window detection.
    pub windows: DetectionScore,
}

impl FacadeScore {
    /// Scores a parse (its label map and window rectangles) against a labelled photo.
    pub fn of(
        pred: &LabelMap,
        pred_windows: &[Rect],
        truth: &LabelMap,
    ) -> Result<Self, FacadeError> {
        Ok(FacadeScore {
            pixels: PixelScore::of(pred, truth)?,
            windows: DetectionScore::of(pred_windows, &window_instances(truth)),
        })
    }
}

fn same_size(a: &LabelMap, b: &LabelMap) -> Result<(), FacadeError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(FacadeError::Size {
            what: format!(
                "prediction is {}×{}, ground truth {}×{}",
                a.width, a.height, b.width, b.height
            ),
        });
    }
    Ok(())
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_scores_leave_ignored_pixels_out() {
        let mut truth = LabelMap::filled(10, 10, Class::Wall);
        truth.paint(&Rect::new(0, 0, 4, 5), Class::Window); // 20 window pixels
        truth.paint(&Rect::new(0, 9, 10, 10), Class::Ignore); // 10 ignored
        let mut pred = LabelMap::filled(10, 10, Class::Wall);
        pred.paint(&Rect::new(2, 0, 6, 5), Class::Window); // 10 right, 10 wrong
        let s = PixelScore::of(&pred, &truth).unwrap();
        // 90 scored pixels, 20 wrong
        assert!((s.accuracy() - 70.0 / 90.0).abs() < 1e-12);
        assert!((s.iou(Class::Window) - 10.0 / 30.0).abs() < 1e-12);
        let all_wall = PixelScore::of(&LabelMap::filled(10, 10, Class::Wall), &truth).unwrap();
        assert!((all_wall.accuracy() - 70.0 / 90.0).abs() < 1e-12);
        assert_eq!(all_wall.iou(Class::Window), 0.0);
        assert!(PixelScore::of(&LabelMap::filled(9, 10, Class::Wall), &truth).is_err());
    }

    #[test]
    fn detection_counts_matches_at_half_overlap() {
        let truth = [
            Instance {
                rect: Rect::new(0, 0, 10, 10),
                dont_care: false,
            },
            Instance {
                rect: Rect::new(20, 0, 30, 10),
                dont_care: false,
            },
            Instance {
                rect: Rect::new(40, 0, 50, 10),
                dont_care: true,
            },
        ];
        // one good hit, one too-shifted guess (IoU 1/3), one on the don't-care window
        let pred = [
            Rect::new(1, 0, 11, 10),
            Rect::new(25, 0, 35, 10),
            Rect::new(40, 0, 50, 10),
        ];
        let s = DetectionScore::of(&pred, &truth);
        assert_eq!(
            (s.true_positives, s.false_positives, s.false_negatives),
            (1, 1, 1)
        );
        assert!((s.f1() - 0.5).abs() < 1e-12);
        // the optimal assignment, not a greedy one: the first guess overlaps both windows
        // equally (IoU 7/13); taking the left one would leave the exact second guess only
        // the right window (IoU 0.25)
        let truth2 = [
            Instance {
                rect: Rect::new(0, 0, 10, 10),
                dont_care: false,
            },
            Instance {
                rect: Rect::new(6, 0, 16, 10),
                dont_care: false,
            },
        ];
        let pred2 = [Rect::new(3, 0, 13, 10), Rect::new(0, 0, 10, 10)];
        let s2 = DetectionScore::of(&pred2, &truth2);
        assert_eq!(s2.true_positives, 2, "{s2:?}");
        assert_eq!(DetectionScore::of(&[], &[]).f1(), 1.0);
    }
}
