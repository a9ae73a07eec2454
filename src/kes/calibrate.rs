//! From a fabric's measurements to a [`MeasuredLaw`], and fitting.
//!
//! Each deformation mode is built from the best data the fabric file has:
//! - **measured curves** become the elastic backbone directly (a loop's mean branch, its
//!   half-width the friction); a shear curve has the standard test's tension contribution
//!   (W tan φ, which the instrument reads along with the fabric's own shear force) removed;
//! - **KES parameters** only: tension follows a power law through (EMT, Fm) whose linearity is
//!   LT (F = Fm (ε/εm)^p, LT = 2/(p + 1)), with a friction share μ set by RT (loading carries
//!   (1 + μ) F_el, unloading (1 − μ) F_el); shear is G with a friction threshold a + c|φ|
//!   through 2HG/2 at 0.5° and 2HG5/2 at 5°; bending is B with a constant friction moment
//!   2HB/2.
//!
//! Then **fitting** (as Charfi & Gagalowicz fitted viscosity): the virtual rigs run on a coarse
//! sample, the KES parameters are computed from the simulated curves with the standard
//! formulas, and the model parameters are corrected by the differences until the virtual
//! experiment reproduces the targets (fixed-point iteration, a few rounds).

use std::sync::Arc;

use crate::cloth::{ClothError, Direction, Friction, MaterialLaw, MeasuredLaw, ResponseCurve};

use super::parameters::interp;
use super::rig::{self, RigCurve, RigMesh};

/// The standard test conditions (SI), adapted to the range a fabric's curves cover.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Protocol {
    /// Maximum tensile load (N/m), warp then weft.
    pub tensile_fm: [f64; 2],
    /// Tension held during the shear test (N/m).
    pub shear_tension: f64,
    /// Shear amplitude (rad).
    pub shear_amplitude: f64,
    /// Bending amplitude (1/m), warp then weft.
    pub bending_amplitude: [f64; 2],
}

/// Angles of the KES shear windows (rad).
pub fn deg(x: f64) -> f64 {
    x.to_radians()
}

/// Where a mode's law came from and its fitted parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TensileModel {
    /// Elastic backbone from a measured curve, friction share μ from its loop (0 without one).
    Curve {
        /// Friction share.
        mu: f64,
    },
    /// Power law through (em, Fm) with linearity `lt`, friction share from recovery `rt`.
    Kes {
        /// Strain at Fm of the backbone scale.
        em: f64,
        /// Linearity LT of the loading curve.
        lt: f64,
        /// Tensile resilience RT (fraction) the friction share is set from.
        rt: f64,
    },
}

/// Shear model: elastic part and friction threshold a + c|φ|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearModel {
    /// Elastic shear rigidity (N/m per rad), when linear.
    pub g_el: f64,
    /// Friction threshold at φ = 0 (N/m).
    pub a: f64,
    /// Threshold growth (N/m per rad).
    pub c: f64,
}

/// Bending model: elastic rigidity and friction moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendingModel {
    /// Elastic bending rigidity (N·m), when linear.
    pub b_el: f64,
    /// Friction moment threshold (N).
    pub hb: f64,
}

fn secant_of(fm: f64, em: f64) -> f64 {
    let s = fm / em;
    if s.is_finite() {
        s
    } else {
        0.0
    }
}

/// Builds the elastic tension curve and friction of a KES power-law model.
fn kes_tension(fm: f64, em: f64, lt: f64, rt: f64) -> (ResponseCurve, f64, Option<Friction>) {
    let p = (2.0 / lt.clamp(0.05, 1.0) - 1.0).max(1.0);
    let mu = ((1.0 - rt) / (1.0 + rt)).clamp(0.0, 0.95);
    let pts: Vec<[f64; 2]> = (1..=60)
        .map(|k| {
            let e = em * 1.5 * k as f64 / 60.0;
            [e, fm * (e / em).powf(p) / (1.0 + mu)]
        })
        .collect();
    // em > 0 and Fm > 0 are checked when the model is built, so the points are finite
    let curve =
        ResponseCurve::new(&pts).unwrap_or_else(|_| ResponseCurve::linear(secant_of(fm, em)));
    let secant = fm / em;
    let fr = (mu > 0.0).then_some(Friction {
        stick: 30.0 * secant,
        base: 0.0,
        slope: mu,
    });
    (curve, 0.1 * secant / (1.0 + mu), fr)
}

/// Mean branch and friction share of a loop (loading, unloading), sampled on the loading x.
fn loop_split(loading: &[[f64; 2]], unloading: &[[f64; 2]]) -> (Vec<[f64; 2]>, f64) {
    if unloading.len() < 2 {
        return (loading.to_vec(), 0.0);
    }
    let mut un = unloading.to_vec();
    un.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let (mut num, mut den) = (0.0, 0.0);
    let mut mean = Vec::with_capacity(loading.len());
    for p in loading {
        match interp(&un, p[0]) {
            Some(u) if p[1] > 0.0 => {
                num += p[1] - u;
                den += p[1] + u;
                mean.push([p[0], 0.5 * (p[1] + u)]);
            }
            _ => mean.push(*p),
        }
    }
    let mu = if den > 0.0 { num / den } else { 0.0 };
    (mean, mu.clamp(0.0, 0.95))
}

/// Everything needed to build the law of one fabric and adjust it.
#[derive(Debug, Clone, PartialEq)]
pub struct LawModel {
    /// Areal density (kg/m²).
    pub density: f64,
    /// Test conditions.
    pub protocol: Protocol,
    /// Tensile models (warp, weft) and their elastic curves.
    pub tension: [TensileModel; 2],
    tension_curves: [Option<ResponseCurve>; 2],
    /// Shear model; `shear_curve` replaces the linear elastic part when measured.
    pub shear: ShearModel,
    shear_curve: Option<ResponseCurve>,
    /// The elastic shear points behind `shear_curve` (rad, N/m), adjusted by fitting.
    shear_points: Vec<[f64; 2]>,
    /// Bending models (warp, weft).
    pub bending: [BendingModel; 2],
    bending_curves: [Option<ResponseCurve>; 2],
}

/// Inputs for one mode: a loop (loading, unloading) in SI, or KES parameters.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModeData {
    /// Loading branch (x increasing from 0), SI.
    pub loading: Vec<[f64; 2]>,
    /// Unloading branch, SI (may be empty).
    pub unloading: Vec<[f64; 2]>,
}

/// The measurements of a fabric in SI, as the calibration needs them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Measurements {
    /// Areal density (kg/m²).
    pub density: f64,
    /// Maximum tensile load of the protocol (N/m).
    pub tensile_fm: f64,
    /// Tensile curves, warp then weft.
    pub tensile_curve: [Option<ModeData>; 2],
    /// (EMT fraction, LT, RT fraction) per direction.
    pub tensile_kes: [(Option<f64>, Option<f64>, Option<f64>); 2],
    /// Shear curve (loading from 0 and, if any, the return branch).
    pub shear_curve: Option<ModeData>,
    /// (G N/(m·rad), 2HG N/m, 2HG5 N/m).
    pub shear_kes: (Option<f64>, Option<f64>, Option<f64>),
    /// Bending curves, warp then weft.
    pub bending_curve: [Option<ModeData>; 2],
    /// (B N·m, 2HB N) per direction.
    pub bending_kes: [(Option<f64>, Option<f64>); 2],
}

/// Standard shear tension, 10 gf/cm (N/m).
pub const SHEAR_TENSION: f64 = 10.0 * 0.980665;
/// Standard shear amplitude, 8°.
pub const SHEAR_AMPLITUDE_DEG: f64 = 8.0;
/// Standard bending amplitude, 2.5 1/cm (1/m).
pub const BENDING_AMPLITUDE: f64 = 250.0;

impl LawModel {
    /// The initial model of `m` (before fitting). Errors name the missing data.
    pub fn new(m: &Measurements) -> Result<Self, String> {
        let mut protocol = Protocol {
            tensile_fm: [m.tensile_fm; 2],
            shear_tension: SHEAR_TENSION,
            shear_amplitude: deg(SHEAR_AMPLITUDE_DEG),
            bending_amplitude: [BENDING_AMPLITUDE; 2],
        };
        let names = ["warp", "weft"];
        let mut tension = [TensileModel::Curve { mu: 0.0 }; 2];
        let mut tension_curves: [Option<ResponseCurve>; 2] = [None, None];
        for d in 0..2 {
            if let Some(c) = &m.tensile_curve[d] {
                let (mean, mu) = loop_split(&c.loading, &c.unloading);
                let curve = ResponseCurve::new(&mean)
                    .map_err(|e| format!("curves.tensile_{}: {e}", names[d]))?;
                protocol.tensile_fm[d] = m.tensile_fm.min(curve.end()[1]);
                tension_curves[d] = Some(curve);
                tension[d] = TensileModel::Curve { mu };
            } else if let (Some(emt), lt, rt) = m.tensile_kes[d] {
                if emt <= 0.0 {
                    return Err(format!(
                        "kes.{}.EMT must be > 0 to build a tensile law, got {emt}",
                        names[d]
                    ));
                }
                tension[d] = TensileModel::Kes {
                    em: emt,
                    lt: lt.unwrap_or(1.0),
                    rt: rt.unwrap_or(1.0),
                };
            } else {
                return Err(format!(
                    "no tensile data for the {}: need curves.tensile_{} or kes.{}.EMT",
                    names[d], names[d], names[d]
                ));
            }
        }
        let mut shear = ShearModel {
            g_el: 0.0,
            a: 0.0,
            c: 0.0,
        };
        let mut shear_curve = None;
        let mut shear_points = Vec::new();
        if let Some(c) = &m.shear_curve {
            let (mean, mu) = loop_split(&c.loading, &c.unloading);
            let amp = mean.last().map_or(0.0, |p| p[0]);
            protocol.shear_amplitude = protocol.shear_amplitude.min(amp);
            // remove the tension's share, which the rig adds back
            let el: Vec<[f64; 2]> = mean
                .iter()
                .filter(|p| p[0] >= 0.0)
                .map(|p| [p[0], p[1] - SHEAR_TENSION * p[0].tan()])
                .collect();
            shear_curve = Some(ResponseCurve::new(&el).map_err(|e| format!("curves.shear: {e}"))?);
            shear_points = el.clone();
            if mu > 0.0 {
                let end = el.last().map_or(0.0, |p| p[1]);
                shear.a = mu * end;
            }
        } else if let (Some(g), hg, hg5) = m.shear_kes {
            let (h1, h5) = (hg.unwrap_or(0.0) / 2.0, hg5.or(hg).unwrap_or(0.0) / 2.0);
            let c = ((h5 - h1) / (deg(5.0) - deg(0.5))).max(0.0);
            shear = ShearModel {
                g_el: (g - c - SHEAR_TENSION).max(0.05 * g),
                a: (h1 - c * deg(0.5)).max(0.0),
                c,
            };
        } else {
            return Err("no shear data: need curves.shear or kes.warp.G".into());
        }
        let mut bending = [BendingModel { b_el: 0.0, hb: 0.0 }; 2];
        let mut bending_curves: [Option<ResponseCurve>; 2] = [None, None];
        for d in 0..2 {
            if let Some(c) = &m.bending_curve[d] {
                let (mean, mu) = loop_split(&c.loading, &c.unloading);
                let curve = ResponseCurve::new(&mean)
                    .map_err(|e| format!("curves.bending_{}: {e}", names[d]))?;
                protocol.bending_amplitude[d] = BENDING_AMPLITUDE.min(curve.end()[0]);
                bending[d].hb = mu * curve.end()[1];
                bending_curves[d] = Some(curve);
            } else if let (Some(b), hb) = m.bending_kes[d] {
                bending[d] = BendingModel {
                    b_el: b,
                    hb: hb.unwrap_or(0.0) / 2.0,
                };
            } else {
                return Err(format!(
                    "no bending data for the {}: need curves.bending_{} or kes.{}.B",
                    names[d], names[d], names[d]
                ));
            }
        }
        Ok(LawModel {
            density: m.density,
            protocol,
            tension,
            tension_curves,
            shear,
            shear_curve,
            shear_points,
            bending,
            bending_curves,
        })
    }

    /// True when any mode is built from KES parameters (so fitting applies).
    pub fn has_kes_modes(&self) -> bool {
        self.tension
            .iter()
            .any(|t| matches!(t, TensileModel::Kes { .. }))
            || self.shear_is_kes()
            || self.shear_is_curve()
            || (0..2).any(|d| self.bending_is_kes(d))
    }

    /// True when shear comes from a measured curve.
    pub fn shear_is_curve(&self) -> bool {
        self.shear_curve.is_some()
    }

    /// Corrects the elastic shear curve by `delta(x)` (N/m) at its points — the fitting step
    /// for a measured shear curve (the specimen's free edges and the tension make the rig
    /// read less than the material law). Returns the largest relative correction.
    pub fn correct_shear_curve(&mut self, delta: impl Fn(f64) -> Option<f64>) -> f64 {
        let mut worst: f64 = 0.0;
        for p in self.shear_points.iter_mut().filter(|p| p[0] > 0.0) {
            if let Some(d) = delta(p[0]) {
                worst = worst.max((d / p[1].abs().max(1e-12)).abs());
                p[1] += d;
            }
        }
        if let Ok(c) = ResponseCurve::new(&self.shear_points) {
            self.shear_curve = Some(c);
        }
        worst
    }

    /// True when shear comes from KES parameters.
    pub fn shear_is_kes(&self) -> bool {
        self.shear_curve.is_none()
    }

    /// True when bending along direction `d` (0 warp, 1 weft) comes from KES parameters.
    pub fn bending_is_kes(&self, d: usize) -> bool {
        self.bending_curves[d].is_none()
    }

    /// The material law of the model's current parameters.
    pub fn law(&self) -> MeasuredLaw {
        let mut tension = [ResponseCurve::linear(0.0), ResponseCurve::linear(0.0)];
        let mut compression = [0.0; 2];
        let mut tension_friction = [None, None];
        for d in 0..2 {
            let fm = self.protocol.tensile_fm[d];
            match (self.tension[d], &self.tension_curves[d]) {
                (TensileModel::Curve { mu }, Some(c)) => {
                    let end = c.end();
                    let secant = if end[0] > 0.0 { end[1] / end[0] } else { 1.0 };
                    tension[d] = c.clone();
                    compression[d] = c.initial_slope().max(0.1 * secant);
                    tension_friction[d] = (mu > 0.0).then_some(Friction {
                        stick: 30.0 * secant,
                        base: 0.0,
                        slope: mu,
                    });
                }
                (TensileModel::Kes { em, lt, rt }, _) => {
                    let (c, comp, fr) = kes_tension(fm, em, lt, rt);
                    tension[d] = c;
                    compression[d] = comp;
                    tension_friction[d] = fr;
                }
                (TensileModel::Curve { .. }, None) => {}
            }
        }
        let shear = match &self.shear_curve {
            Some(c) => c.clone(),
            None => ResponseCurve::linear(self.shear.g_el),
        };
        let amp = self.protocol.shear_amplitude.max(deg(1.0));
        let top = self.shear.a + self.shear.c * amp;
        let shear_friction = (top > 0.0).then(|| Friction {
            stick: top / deg(0.05),
            base: self.shear.a,
            slope: if self.shear.g_el > 0.0 {
                self.shear.c / self.shear.g_el
            } else {
                0.0
            },
        });
        let mut bending = [ResponseCurve::linear(0.0), ResponseCurve::linear(0.0)];
        let mut bending_friction = [None, None];
        for d in 0..2 {
            bending[d] = match &self.bending_curves[d] {
                Some(c) => c.clone(),
                None => ResponseCurve::linear(self.bending[d].b_el),
            };
            let hb = self.bending[d].hb;
            bending_friction[d] = (hb > 0.0).then_some(Friction {
                stick: hb / 2.0,
                base: hb,
                slope: 0.0,
            });
        }
        MeasuredLaw {
            tension,
            compression,
            shear,
            bending,
            tension_friction,
            shear_friction,
            bending_friction,
        }
    }
}

/// The simulated curves of one run of every rig.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RigRun {
    /// Tensile paths, warp then weft.
    pub tensile: [RigCurve; 2],
    /// Shear path.
    pub shear: RigCurve,
    /// Bending paths, warp then weft.
    pub bending: [RigCurve; 2],
}

/// Which rigs to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tests {
    /// Tensile, warp and weft.
    pub tensile: bool,
    /// Shear.
    pub shear: bool,
    /// Pure bending, warp and weft.
    pub bending: bool,
}

impl Tests {
    /// Every rig.
    pub const ALL: Tests = Tests {
        tensile: true,
        shear: true,
        bending: true,
    };
}

/// Runs the rigs of `tests` on `mesh` with the model's law (the others stay empty).
pub fn run_rigs(model: &LawModel, mesh: RigMesh, tests: Tests) -> Result<RigRun, ClothError> {
    let law: Arc<dyn MaterialLaw> = Arc::new(model.law());
    let p = &model.protocol;
    let dirs = [Direction::Warp, Direction::Weft];
    let mut run = RigRun::default();
    for d in 0..2 {
        if tests.tensile {
            run.tensile[d] =
                rig::tensile(law.clone(), model.density, dirs[d], p.tensile_fm[d], mesh)?;
        }
        if tests.bending {
            run.bending[d] = rig::bending(
                law.clone(),
                model.density,
                dirs[d],
                p.bending_amplitude[d],
                mesh,
            )?;
        }
    }
    if tests.shear {
        run.shear = rig::shear(law, model.density, p.shear_tension, p.shear_amplitude, mesh)?;
    }
    Ok(run)
}
