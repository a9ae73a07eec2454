//! `Silhouettes`: a mannequin seen from the front and from the back in its own frame
//! ([`BodyFrame`]), as depth maps on a regular grid of the (left, up) plane: for each covered
//! cell the frontmost and the backmost skin depth. From them come the body's cross-sections at
//! any height (the runs of covered cells and their depth bounds) and its landmark heights
//! (crotch, hip, waist, armpit/chest, shoulder, neck, knee, ankle).

use super::body_frame::BodyFrame;
use crate::garment::PatternError;
use crate::geometry::Vec3;

/// Front and back depth maps of a body on a grid of `cell`-sized squares.
#[derive(Debug, Clone)]
pub struct Silhouettes {
    /// The body's frame.
    pub frame: BodyFrame,
    /// Cell size (m).
    pub cell: f64,
    /// Left coordinate of column 0's centre (m).
    pub s0: f64,
    /// Height of row 0's centre (m).
    pub h0: f64,
    /// Columns.
    pub ns: usize,
    /// Rows.
    pub nh: usize,
    /// Frontmost depth per cell (row-major, `f64::NEG_INFINITY` where uncovered).
    pub front: Vec<f64>,
    /// Backmost depth per cell (`f64::INFINITY` where uncovered).
    pub back: Vec<f64>,
}

/// Heights of body landmarks in the body frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmarks {
    /// Top of the head.
    pub top: f64,
    /// Narrowest neck.
    pub neck: f64,
    /// Top of the shoulders (where the torso narrows to the neck).
    pub shoulder: f64,
    /// Chest: just below the armpits.
    pub chest: f64,
    /// Armpits: where the arms leave the torso.
    pub armpit: f64,
    /// Narrowest torso between hips and chest.
    pub waist: f64,
    /// Widest torso just above the crotch.
    pub hip: f64,
    /// Where the legs join.
    pub crotch: f64,
    /// Knees (halfway from crotch to ankles, a little below).
    pub knee: f64,
    /// Ankles.
    pub ankle: f64,
    /// Soles.
    pub floor: f64,
}

impl Landmarks {
    /// The height of a landmark by name.
    pub fn get(&self, name: &str) -> Option<f64> {
        Some(match name {
            "top" => self.top,
            "neck" => self.neck,
            "shoulder" => self.shoulder,
            "chest" => self.chest,
            "armpit" => self.armpit,
            "waist" => self.waist,
            "hip" => self.hip,
            "crotch" => self.crotch,
            "knee" => self.knee,
            "ankle" => self.ankle,
            "floor" => self.floor,
            _ => return None,
        })
    }
}

impl Silhouettes {
    /// Rasterizes a skin mesh seen along its frame's front axis on cells of `cell` metres.
    pub fn of(
        frame: BodyFrame,
        positions: &[Vec3],
        triangles: &[[usize; 3]],
        cell: f64,
    ) -> Result<Silhouettes, PatternError> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(PatternError::Parameter(format!(
                "silhouette cell must be > 0, got {cell}"
            )));
        }
        let pts: Vec<[f64; 3]> = positions.iter().map(|p| frame.to_body(p)).collect();
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in &pts {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let ns = ((hi[0] - lo[0]) / cell).ceil() as usize + 3;
        let nh = ((hi[1] - lo[1]) / cell).ceil() as usize + 3;
        if ns * nh > 50_000_000 {
            return Err(PatternError::Parameter(format!(
                "silhouette grid of {ns}×{nh} cells is too large (cell {cell} m)"
            )));
        }
        let (s0, h0) = (lo[0] - cell, lo[1] - cell);
        let mut sil = Silhouettes {
            frame,
            cell,
            s0,
            h0,
            ns,
            nh,
            front: vec![f64::NEG_INFINITY; ns * nh],
            back: vec![f64::INFINITY; ns * nh],
        };
        for t in triangles {
            let [a, b, c] = [pts[t[0]], pts[t[1]], pts[t[2]]];
            let den = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            let cmin = |k: usize| a[k].min(b[k]).min(c[k]);
            let cmax = |k: usize| a[k].max(b[k]).max(c[k]);
            let (j0, j1) = (sil.col(cmin(0)), sil.col(cmax(0)));
            let (i0, i1) = (sil.row(cmin(1)), sil.row(cmax(1)));
            for i in i0..=i1 {
                let h = h0 + i as f64 * cell;
                for j in j0..=j1 {
                    let s = s0 + j as f64 * cell;
                    let d = if den.abs() < 1e-18 {
                        None
                    } else {
                        let u = ((b[0] - s) * (c[1] - h) - (c[0] - s) * (b[1] - h)) / den;
                        let v = ((c[0] - s) * (a[1] - h) - (a[0] - s) * (c[1] - h)) / den;
                        let w = 1.0 - u - v;
                        (u >= -1e-9 && v >= -1e-9 && w >= -1e-9)
                            .then(|| u * a[2] + v * b[2] + w * c[2])
                    };
                    if let Some(d) = d {
                        sil.splat(i, j, d);
                    }
                }
            }
            // tiny triangles: their corners still mark their cells
            for p in [a, b, c] {
                let (i, j) = (sil.row(p[1]), sil.col(p[0]));
                sil.splat(i, j, p[2]);
            }
        }
        Ok(sil)
    }

    #[inline]
    fn splat(&mut self, i: usize, j: usize, d: f64) {
        let k = i * self.ns + j;
        self.front[k] = self.front[k].max(d);
        self.back[k] = self.back[k].min(d);
    }

    /// The column whose cell holds left coordinate `s` (clamped to the grid).
    pub fn col(&self, s: f64) -> usize {
        (((s - self.s0) / self.cell).round().max(0.0) as usize).min(self.ns - 1)
    }

    /// The row whose cell holds height `h` (clamped to the grid).
    pub fn row(&self, h: f64) -> usize {
        (((h - self.h0) / self.cell).round().max(0.0) as usize).min(self.nh - 1)
    }

    /// Left coordinate of column `j`'s centre.
    pub fn s_of(&self, j: usize) -> f64 {
        self.s0 + j as f64 * self.cell
    }

    /// Height of row `i`'s centre.
    pub fn h_of(&self, i: usize) -> f64 {
        self.h0 + i as f64 * self.cell
    }

    /// Whether cell (`i`, `j`) is covered by the body.
    #[inline]
    pub fn covered(&self, i: usize, j: usize) -> bool {
        self.front[i * self.ns + j] > f64::NEG_INFINITY
    }

    /// Front and back depth of cell (`i`, `j`), if covered.
    #[inline]
    pub fn depths(&self, i: usize, j: usize) -> Option<(f64, f64)> {
        let k = i * self.ns + j;
        self.covered(i, j).then(|| (self.front[k], self.back[k]))
    }

    /// Runs of covered columns in row `i` as inclusive column ranges; gaps of one cell are
    /// bridged.
    pub fn runs(&self, i: usize) -> Vec<(usize, usize)> {
        let mut out: Vec<(usize, usize)> = Vec::new();
        for j in 0..self.ns {
            if !self.covered(i, j) {
                continue;
            }
            match out.last_mut() {
                Some(r) if j <= r.1 + 2 => r.1 = j,
                _ => out.push((j, j)),
            }
        }
        out
    }

    /// The run of row `i` that holds column `j`, or none.
    pub fn run_at(&self, i: usize, j: usize) -> Option<(usize, usize)> {
        self.runs(i).into_iter().find(|r| r.0 <= j && j <= r.1)
    }

    /// Width (m) of the run of row `i` through the body's centre line (0 when uncovered).
    pub fn centre_width(&self, i: usize) -> f64 {
        let c = self.col(0.0);
        self.run_at(i, c)
            .map_or(0.0, |r| (r.1 - r.0 + 1) as f64 * self.cell)
    }

    /// The body's landmark heights, read off the width of the centre run row by row.
    pub fn landmarks(&self) -> Result<Landmarks, PatternError> {
        let width: Vec<f64> = (0..self.nh).map(|i| self.centre_width(i)).collect();
        let floor = self.frame.floor;
        let top = self.frame.top;
        let tall = top - floor;
        let row = |h: f64| self.row(h);
        let fail = |what: &str| {
            PatternError::Parameter(format!(
                "cannot find the body's {what} from its silhouette (is it a standing human?)"
            ))
        };
        // crotch: lowest row above 30 % of the height where the centre line is covered
        let crotch_row = (row(floor + 0.3 * tall)..row(floor + 0.7 * tall))
            .find(|&i| width[i] > 0.0)
            .ok_or_else(|| fail("crotch"))?;
        let arg = |from: usize, to: usize, better: &dyn Fn(f64, f64) -> bool| {
            let mut best = from;
            for i in from..to.min(self.nh) {
                if better(width[i], width[best]) {
                    best = i;
                }
            }
            best
        };
        let band = |m: f64| (m / self.cell).round() as usize;
        // armpit: first row well above the hands where the centre run jumps wider (arms join)
        let mut armpit_row = None;
        for i in crotch_row + band(0.25)..self.nh.saturating_sub(1) {
            if width[i] > width[i - 1] + 4.0 * self.cell {
                armpit_row = Some(i);
                break;
            }
        }
        let armpit_row = armpit_row.ok_or_else(|| fail("armpits"))?;
        let waist_row = arg(
            crotch_row + band(0.1),
            armpit_row.saturating_sub(band(0.1)),
            &|a, b| a < b,
        );
        // hip: widest torso between crotch and waist, on rows where the hands hang apart
        let apart: Vec<usize> = (crotch_row + band(0.02)..waist_row)
            .filter(|&i| self.runs(i).len() >= 3)
            .collect();
        let hip_row = match apart.first() {
            Some(_) => *apart
                .iter()
                .max_by(|&&a, &&b| width[a].total_cmp(&width[b]).then(b.cmp(&a)))
                .unwrap_or(&crotch_row),
            None => crotch_row + (waist_row - crotch_row) * 2 / 5,
        };
        // neck: narrowest row in the band 78–92 % of the height
        let neck_row = arg(row(floor + 0.8 * tall), row(floor + 0.9 * tall), &|a, b| {
            a > 0.0 && a < b
        });
        // shoulder: highest row below the neck still wider than twice the neck
        let shoulder_row = (armpit_row..neck_row)
            .rev()
            .find(|&i| width[i] > 2.0 * width[neck_row])
            .ok_or_else(|| fail("shoulders"))?;
        let h = |i: usize| self.h_of(i);
        let ankle = floor + 0.045 * tall;
        let crotch = h(crotch_row);
        Ok(Landmarks {
            top,
            neck: h(neck_row),
            shoulder: h(shoulder_row),
            chest: h(armpit_row) - 0.03,
            armpit: h(armpit_row),
            waist: h(waist_row),
            hip: h(hip_row),
            crotch,
            knee: ankle + 0.45 * (crotch - ankle),
            ankle,
            floor,
        })
    }
}
