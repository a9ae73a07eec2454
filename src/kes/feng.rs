//! The 618 cantilever-measured fabrics of Feng et al. 2022 (`fabrics/feng2022_bending.csv` of
//! the shared data: areal density and, per direction, M(κ) = k1·κ + k2·κ² per unit width)
//! through the virtual bending rig: each fabric's measured bending curve becomes the law's
//! bending curve, the KES-FB2 rig bends the simulated sample, and a quadratic fitted to the
//! rig's reading is compared with the measured k1, k2.
//!
//! The CSV holds bending only. The lab's law needs tensile and shear data too; they are the
//! typical shirting values of [`TYPICAL_KES`] (pure bending barely depends on them), stated in
//! each fabric's provenance.

use std::path::Path;

use super::error::KesError;
use super::fabric::{Curve, FabricCurves, FabricSpec, KesValues, STANDARD_FM};
use super::kes_param::KesParam;
use super::lab::{self, LabOptions};
use super::rig::RigMesh;
use super::rig_parameters::branches;
use super::units;

/// Largest curvature of the measured regime used (1/m): Feng's cantilevers bend a strip to
/// curvatures of a few tens of 1/m; the curve is also cut at half the curvature where the
/// fitted quadratic stops rising (k2 < 0), where it no longer describes the fabric.
pub const KAPPA_MAX: f64 = 50.0;

/// Points of each bending curve handed to the lab.
const CURVE_POINTS: usize = 21;

/// Tensile and shear KES values used for every Feng fabric (the CSV has none): those of
/// `kawabata/fabrics/shirting-cotton.json`, KES units: EMT %, LT, RT %, G gf/(cm·deg),
/// 2HG and 2HG5 gf/cm.
pub const TYPICAL_KES: [(KesParam, f64); 6] = [
    (KesParam::Emt, 3.0),
    (KesParam::Lt, 0.65),
    (KesParam::Rt, 60.0),
    (KesParam::G, 0.9),
    (KesParam::Hg2, 1.2),
    (KesParam::Hg52, 2.5),
];

/// One fabric of the CSV, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct FengFabric {
    /// Data row (0-based, the header not counted).
    pub row: usize,
    /// Areal density (kg/m²).
    pub density: f64,
    /// k1 (N·m) warp, weft, diagonal.
    pub k1: [f64; 3],
    /// k2 (N·m²) warp, weft, diagonal.
    pub k2: [f64; 3],
}

/// Reads every fabric of the CSV (header line, then `density, k1 ×3, k2 ×3` in the units of
/// the header: kg/m², 1e-9 N·m, 1e-12 N·m²). Errors name the file and the line.
pub fn read_feng(path: &Path) -> Result<Vec<FengFabric>, KesError> {
    let file = path.display().to_string();
    let err = |line: usize, message: String| KesError::Field {
        file: file.clone(),
        field: format!("line {line}"),
        message,
    };
    let text = crate::limits::read_to_string(path).map_err(|e| err(0, e.to_string()))?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    if !header.starts_with("density[kg.m-2]") {
        return Err(err(
            1,
            "expected the header `density[kg.m-2], linear warp[SI*1e9], …`".into(),
        ));
    }
    let mut out = Vec::new();
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let n = i + 2;
        crate::limits::check_count(
            &format!("{file}: rows"),
            out.len() as u64 + 1,
            "max_elements",
            crate::limits::get().max_elements,
        )
        .map_err(|e| err(n, e.to_string()))?;
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| err(n, format!("not a number: {e}")))?;
        if v.len() != 7 || v.iter().any(|x| !x.is_finite()) {
            return Err(err(n, format!("expected 7 finite numbers, got `{line}`")));
        }
        if v[0] <= 0.0 || v[1..4].iter().any(|&k| k <= 0.0) {
            return Err(err(n, "density and k1 must be positive".into()));
        }
        out.push(FengFabric {
            row: out.len(),
            density: v[0],
            k1: [v[1] * 1e-9, v[2] * 1e-9, v[3] * 1e-9],
            k2: [v[4] * 1e-12, v[5] * 1e-12, v[6] * 1e-12],
        });
    }
    Ok(out)
}

/// Reads one fabric (0-based data row) of the CSV.
pub fn read_feng_row(path: &Path, row: usize) -> Result<FengFabric, KesError> {
    let all = read_feng(path)?;
    let n = all.len();
    all.into_iter().nth(row).ok_or_else(|| KesError::Field {
        file: path.display().to_string(),
        field: "row".into(),
        message: format!(
            "row {row} is past the last row ({n} fabrics, rows 0 … {})",
            n - 1
        ),
    })
}

impl FengFabric {
    /// Moment per unit width (N) along direction `d` (0 warp, 1 weft, 2 diagonal) at
    /// curvature `kappa` (1/m).
    pub fn moment(&self, d: usize, kappa: f64) -> f64 {
        self.k1[d] * kappa + self.k2[d] * kappa * kappa
    }

    /// The end of the curvature range used along `d` (1/m).
    pub fn kappa_max(&self, d: usize) -> f64 {
        if self.k2[d] < 0.0 {
            KAPPA_MAX.min(0.5 * self.k1[d] / (2.0 * -self.k2[d]))
        } else {
            KAPPA_MAX
        }
    }

    /// The measured bending curve along `d`: 21 points from 0 to
    /// [`Self::kappa_max`].
    pub fn curve(&self, d: usize) -> Curve {
        let km = self.kappa_max(d);
        Curve {
            loading: (0..CURVE_POINTS)
                .map(|i| {
                    let k = km * i as f64 / (CURVE_POINTS - 1) as f64;
                    [k, self.moment(d, k)]
                })
                .collect(),
            unloading: Vec::new(),
        }
    }

    /// The fabric as a lab fabric: its bending curves, its density, and [`TYPICAL_KES`].
    pub fn spec(&self) -> FabricSpec {
        let mut kes = KesValues::default();
        for (p, v) in TYPICAL_KES {
            let si = match p {
                KesParam::Emt | KesParam::Rt => v * units::PERCENT,
                KesParam::Lt => v,
                KesParam::G => v * units::GF_PER_CM_DEG,
                _ => v * units::GF_PER_CM,
            };
            kes.set(p, si);
        }
        FabricSpec {
            name: format!("feng2022-row{}", self.row),
            description: format!(
                "Feng et al. 2022, cantilever-measured fabric, row {}",
                self.row
            ),
            provenance: "bending and density: Feng, Huang, Xu, Wang, \"Learning-Based Bending \
                         Stiffness Parameter Estimation by a Drape Tester\", ACM TOG 41(6), 2022 \
                         (doi 10.1145/3550454.3555464), read at run time; tensile and shear: the \
                         typical shirting values of kawabata/fabrics/shirting-cotton.json"
                .into(),
            path: String::new(),
            density: self.density,
            thickness: None,
            warp: kes.clone(),
            weft: kes,
            curves: FabricCurves {
                bending_warp: Some(self.curve(0)),
                bending_weft: Some(self.curve(1)),
                bending_bias: Some(self.curve(2)),
                ..FabricCurves::default()
            },
            tensile_fm: STANDARD_FM,
        }
    }
}

/// Least-squares M = a·κ + b·κ² through the origin over the points with 0 < κ ≤ `kappa_max`;
/// `None` with fewer than two such points or a singular system.
pub fn fit_quadratic(points: &[[f64; 2]], kappa_max: f64) -> Option<(f64, f64)> {
    let (mut s2, mut s3, mut s4, mut sm1, mut sm2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut n = 0;
    for p in points
        .iter()
        .filter(|p| p[0] > 0.0 && p[0] <= kappa_max * (1.0 + 1e-9))
    {
        let (k, m) = (p[0], p[1]);
        s2 += k * k;
        s3 += k * k * k;
        s4 += k * k * k * k;
        sm1 += m * k;
        sm2 += m * k * k;
        n += 1;
    }
    let det = s2 * s4 - s3 * s3;
    if n < 2 || det.abs() <= 1e-12 * s2 * s4 {
        return None;
    }
    Some(((sm1 * s4 - sm2 * s3) / det, (s2 * sm2 - s3 * sm1) / det))
}

/// A fabric through the rig: measured and fitted k1, k2 (warp, weft), the curve errors.
#[derive(Debug, Clone, PartialEq)]
pub struct FengComparison {
    /// The fabric.
    pub fabric: FengFabric,
    /// k1 (N·m) fitted to the rig's reading, warp and weft.
    pub k1_fit: [f64; 2],
    /// k2 (N·m²) fitted to the rig's reading, warp and weft.
    pub k2_fit: [f64; 2],
    /// RMS difference of the rig's curve from the measured one (% of its range), warp, weft.
    pub curve_rms_pct: [f64; 2],
    /// Rig increments whose equilibrium stopped at the iteration cap.
    pub unconverged: usize,
}

/// Runs the virtual bending rig (warp and weft) on a Feng fabric on `mesh` and fits the
/// quadratic to its readings.
pub fn compare(fabric: &FengFabric, mesh: RigMesh) -> Result<FengComparison, String> {
    let opts = LabOptions {
        meshes: vec![("rig".into(), mesh)],
        fit: true,
        cantilever: false,
        tests: super::calibrate::Tests {
            tensile: false,
            shear: false,
            bending: true,
        },
        ..LabOptions::default()
    };
    let report = lab::run_fabric(&fabric.spec(), &opts)?;
    let run = &report
        .runs
        .first()
        .ok_or_else(|| "the lab ran no rig".to_string())?
        .1;
    let mut k1_fit = [0.0; 2];
    let mut k2_fit = [0.0; 2];
    let mut rms = [f64::NAN; 2];
    for d in 0..2 {
        let (virgin, _, _) = branches(&run.bending[d].path);
        let (a, b) = fit_quadratic(&virgin, fabric.kappa_max(d)).ok_or_else(|| {
            format!(
                "row {}: too few rig readings to fit along the {}",
                fabric.row,
                ["warp", "weft"][d]
            )
        })?;
        k1_fit[d] = a;
        k2_fit[d] = b;
        let test = ["bending_warp", "bending_weft"][d];
        if let Some(c) = report.curves.iter().find(|c| c.test == test) {
            rms[d] = c.rms_pct;
        }
    }
    Ok(FengComparison {
        fabric: fabric.clone(),
        k1_fit,
        k2_fit,
        curve_rms_pct: rms,
        unconverged: report.unconverged(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_fit_recovers_exact_coefficients() {
        let pts: Vec<[f64; 2]> = (0..=20)
            .map(|i| {
                let k = 2.5 * i as f64;
                [k, 3e-6 * k - 1e-8 * k * k]
            })
            .collect();
        let (a, b) = fit_quadratic(&pts, 50.0).unwrap();
        assert!((a - 3e-6).abs() < 1e-15, "{a}");
        assert!((b + 1e-8).abs() < 1e-17, "{b}");
    }

    #[test]
    fn curve_stops_before_the_peak() {
        let f = FengFabric {
            row: 0,
            density: 0.1,
            k1: [1.7799e-6, 3.0762e-6, 2.2441e-6],
            k2: [-4e-8, -4.1585e-9, -3.3511e-9],
        };
        // warp: M peaks at k1 / (2|k2|) = 22.2 1/m; the curve ends at half of it
        assert!((f.kappa_max(0) - 0.25 * 1.7799e-6 / 4e-8).abs() < 1e-9);
        assert_eq!(f.kappa_max(1), KAPPA_MAX);
        let c = f.curve(0);
        assert!(c.loading.windows(2).all(|w| w[1][1] > w[0][1]));
    }
}
