//! Import of the ten measured fabrics of Wang, O'Brien & Ramamoorthi 2011 ("Data-Driven
//! Elastic Models for Cloth", ACM TOG 30(4):71, doi 10.1145/2010324.1964966), as distributed
//! with ARCSim, into our fabric format. Their licence (ARCSim's: education, research,
//! not-for-profit) forbids redistribution in a commercial product, so the conversion runs at
//! run time into an output folder; nothing derived from them is committed.
//!
//! ARCSim's reading of the numbers (maths notes §2.1): `density` kg/m²; `stretching` rows of
//! (c11, c12, c22, c33) N/m, row 0 at zero strain, rows 1–5 at principal stretch 1 + 1/6 for
//! principal directions 0°, 22.5°, 45°, 67.5°, 90° from u, interpolated linearly in the strain
//! coordinate 6 (stretch − 1), doubled, in W = ½(k0 Guu² + k2 Gvv² + 2 k1 Guu Gvv + k3 Guv²)
//! with Green strain G; `bending` rows for hinge edges at 0°, 45°, 90° from u, columns at
//! curvature 0, 10, 20, 30, 40 1/m, N·m. We take u as the warp (the files do not say).
//!
//! Conversion (documented in every file's provenance):
//! - tensile (strip-biaxial, width held): k(ε) = 2·lerp(c_row0, c_row, min(6ε, 1)),
//!   F(ε) = (1 + ε) k(ε) (ε + ε²/2), ε = 0 … 1/6 every 0.5 % (warp: c11, row 1; weft: c22, row 5);
//! - tensile along the bias (45°, row 3): the deformation F = I + ε d dᵀ, d = (1, 1)/√2, has
//!   Green strain G = e d dᵀ with e = ε + ε²/2, so G_uu = G_vv = G_uv = e/2 and
//!   W = (e²/8)(k0 + k2 + 2 k1 + k3); the force per width along d is ∂W/∂ε (stiffnesses held,
//!   as ARCSim's forces do): F(ε) = (1 + ε) (e/4)(k0 + k2 + 2 k1 + k3), each k_i =
//!   2·lerp(c_row0, c_row3, min(6ε, 1)) — small-strain slope (c11 + c22 + 2 c12 + c33)/2;
//! - shear as the KES-FB1 instrument would read it under its 10 gf/cm tension:
//!   H(φ) = (c33(φ)/2) φ + T tan φ (T = 10 gf/cm), c33(φ) = lerp(c33_row0, c33_row3, min(3|φ|, 1)),
//!   0 … 8° every 0.5°;
//! - bending: M(κ) = k(κ) κ with k interpolated along the row, 0 … 0.4 1/cm every 0.025 1/cm;
//!   curvature along the warp bends about hinges at 90° from u (row 2), along the weft row 0,
//!   bias row 1, kept up to where M stops rising (several tables soften so fast beyond
//!   30 1/m that M(κ) would fall, which no measured curve does). ARCSim's hinge normalisation
//!   makes the table value the rigidity within ~25 %; we take it as B.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::calibrate::SHEAR_TENSION;
use super::error::KesError;
use super::fabric::{json_files, write_fabric, Curve, FabricCurves, FabricSpec, KesValues};

fn field_err(file: &str, field: &str, message: impl Into<String>) -> KesError {
    KesError::Field {
        file: file.into(),
        field: field.into(),
        message: message.into(),
    }
}

/// A `rows` × `cols` table of finite numbers; columns in `signed` may be negative (the
/// stretching tables are fitted model parameters and hold a few negative entries), the
/// others must be ≥ 0.
fn table(
    v: &Value,
    file: &str,
    key: &str,
    rows: usize,
    cols: usize,
    signed: &[usize],
) -> Result<Vec<Vec<f64>>, KesError> {
    let arr = v
        .get(key)
        .and_then(|a| a.as_array())
        .filter(|a| a.len() == rows)
        .ok_or_else(|| field_err(file, key, format!("expected {rows} rows")))?;
    arr.iter()
        .enumerate()
        .map(|(i, r)| {
            let r = r.as_array().filter(|r| r.len() == cols).ok_or_else(|| {
                field_err(
                    file,
                    &format!("{key}[{i}]"),
                    format!("expected {cols} values"),
                )
            })?;
            r.iter()
                .enumerate()
                .map(|(j, x)| {
                    x.as_f64()
                        .filter(|x| x.is_finite() && (*x >= 0.0 || signed.contains(&j)))
                        .ok_or_else(|| {
                            field_err(
                                file,
                                &format!("{key}[{i}][{j}]"),
                                "must be a finite number (≥ 0 for stiffnesses)",
                            )
                        })
                })
                .collect()
        })
        .collect()
}

/// The conversion, as written into every converted file's provenance.
pub const CONVERSION: &str = "u taken as the warp (the files do not say). Weight = density. \
    Tensile (strip-biaxial, width held, ARCSim Green-strain model): \
    k(e) = 2 lerp(c_row0, c_row, min(6e, 1)), F = (1+e) k(e) (e + e^2/2) N/m, \
    warp c11 with row 1 (0 deg), weft c22 with row 5 (90 deg), e = 0 to 1/6 every 0.5 %, \
    loading only (elastic data). Bias (45 deg, row 3, deformation I + e d d^T, d = (1,1)/sqrt 2, \
    W = (e + e^2/2)^2 (k11 + k22 + 2 k12 + k33)/8, F = dW/de): \
    F = (1+e) (e + e^2/2) (k11 + k22 + 2 k12 + k33)/4, k = 2 lerp(c_row0, c_row3, min(6e, 1)). \
    Tensile Fm = the larger end force of warp and weft. \
    Shear as read by the KES-FB1 under its 10 gf/cm clamp tension: \
    H = (c33(phi)/2) phi + 10 gf/cm tan(phi), c33(phi) = lerp(c33_row0, c33_row3, min(3|phi|, 1)) \
    (c33/2 = ARCSim's engineering shear stiffness, G_uv = phi/2), 0 to 8 deg every 0.5 deg. \
    Bending: M = k(kappa) kappa, k linear in kappa between the columns (0, 10, 20, 30, 40 1/m), \
    every 0.025 1/cm to 0.4 1/cm or to where M stops rising; warp = row 2 (hinge edge at 90 deg), \
    weft = row 0, bias = row 1; ARCSim's hinge normalisation makes the table value the bending \
    rigidity within ~25 % (maths notes 2.1), we take it as B. \
    No KES parameters: they are computed from the curves.";

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Converts one ARCSim/Wang material file.
pub fn import_wang(path: &Path) -> Result<FabricSpec, KesError> {
    let file = path.display().to_string();
    let text = crate::limits::read_to_string(path).map_err(|e| KesError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let v: Value = serde_json::from_str(&text).map_err(|e| KesError::Syntax {
        file: file.clone(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let density = v
        .get("density")
        .and_then(|d| d.as_f64())
        .filter(|d| d.is_finite() && *d > 0.0)
        .ok_or_else(|| field_err(&file, "density", "expected a positive number"))?;
    let st = table(&v, &file, "stretching", 6, 4, &[0, 1, 2, 3])?;
    let bend = table(&v, &file, "bending", 3, 5, &[])?;
    // ε = 0, 0.5 %, … 16.5 %, 1/6
    let strains = || (0..=34).map(|k| (k as f64 * 0.005).min(1.0 / 6.0));
    let tensile = |col: usize, row: usize| -> Curve {
        let loading = strains()
            .map(|e| {
                let kk = 2.0 * lerp(st[0][col], st[row][col], (6.0 * e).min(1.0));
                [e, (1.0 + e) * kk * (e + 0.5 * e * e)]
            })
            .collect();
        Curve {
            loading,
            unloading: Vec::new(),
        }
    };
    let d = std::f64::consts::PI / 180.0;
    let shear = Curve {
        loading: (0..=16)
            .map(|k| {
                let phi = k as f64 * 0.5 * d;
                let c33 = lerp(st[0][3], st[3][3], (3.0 * phi).min(1.0));
                [phi, 0.5 * c33 * phi + SHEAR_TENSION * phi.tan()]
            })
            .collect(),
        unloading: Vec::new(),
    };
    let bending = |row: usize| -> Curve {
        let mut loading: Vec<[f64; 2]> = (0..=16)
            .map(|k| {
                let kappa = k as f64 * 2.5; // 1/m: 0 … 40
                let s = kappa / 10.0;
                let i = (s.floor() as usize).min(3);
                let kk = lerp(bend[row][i], bend[row][i + 1], s - i as f64);
                [kappa, kk * kappa]
            })
            .collect();
        // where the table's rigidity falls faster than 1/κ the moment would decrease, which no
        // measured bending curve does (the strip would be unstable): keep the rising part
        if let Some(k) = (1..loading.len()).find(|&k| loading[k][1] <= loading[k - 1][1]) {
            loading.truncate(k);
        }
        Curve {
            loading,
            unloading: Vec::new(),
        }
    };
    let warp = tensile(0, 1);
    let weft = tensile(2, 5);
    let bias = Curve {
        loading: strains()
            .map(|e| {
                let t = (6.0 * e).min(1.0);
                let k: f64 = (0..4)
                    .map(|c| {
                        let w = if c == 1 { 2.0 } else { 1.0 };
                        w * 2.0 * lerp(st[0][c], st[3][c], t)
                    })
                    .sum();
                [e, (1.0 + e) * 0.25 * k * (e + 0.5 * e * e)]
            })
            .collect(),
        unloading: Vec::new(),
    };
    let end = |c: &Curve| c.loading.last().map_or(0.0, |p| p[1]);
    let fm = end(&warp).max(end(&weft));
    if !(fm.is_finite() && fm > 0.0) {
        return Err(field_err(
            &file,
            "stretching",
            "the warp and weft tables give no tensile force at 1/6 strain",
        ));
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    Ok(FabricSpec {
        description: format!(
            "{name}: measured by Wang, O'Brien & Ramamoorthi 2011 (ARCSim material)"
        ),
        provenance: format!(
            "Converted at run time from {file} (Wang, O'Brien, Ramamoorthi, \"Data-Driven \
             Elastic Models for Cloth\", ACM TOG 30(4):71, 2011, doi 10.1145/2010324.1964966; \
             ARCSim licence: educational, research and not-for-profit use; converted at run \
             time, not redistributed). {CONVERSION}"
        ),
        name,
        path: file.clone(),
        density,
        thickness: None,
        warp: KesValues::default(),
        weft: KesValues::default(),
        curves: FabricCurves {
            tensile_warp: Some(warp),
            tensile_weft: Some(weft),
            tensile_bias: Some(bias),
            shear: Some(shear),
            bending_warp: Some(bending(2)),
            bending_weft: Some(bending(0)),
            bending_bias: Some(bending(1)),
        },
        tensile_fm: fm,
    })
}

/// Converts every `*.json` material of `dir` into our format under `out_dir` (same stems);
/// returns the written paths, sorted.
pub fn import_wang_dir(dir: &Path, out_dir: &Path) -> Result<Vec<PathBuf>, KesError> {
    let files = json_files(dir)?;
    let mut out = Vec::new();
    for f in files {
        let spec = import_wang(&f)?;
        let target = out_dir.join(format!("{}.json", spec.name));
        write_fabric(&target, &spec)?;
        out.push(target);
    }
    Ok(out)
}
