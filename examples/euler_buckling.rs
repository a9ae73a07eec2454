//! Force–shortening of a compressed strip against the pinned elastica (maths notes §5.3): the
//! bending-line model in the virtual compression rig, Choi & Ko's immediate-buckling force of
//! one connection standing for the whole strip, and the table. Writes
//! `out/buckling/force_shortening.{csv,png,svg}` and prints the deviations:
//! `cargo run --release --example euler_buckling`.
use std::path::Path;
use std::sync::Arc;

use emilion::cloth::buckling::choi_ko::buckling_force;
use emilion::cloth::{FabricParameters, MaterialLaw};
use emilion::kes::compression::{Strip, StripEnds};
use emilion::render::plot::{write_plot_pair, write_series_csv, PlotSpec, Series, SeriesStyle};

/// (end rotation °, P/P_cr, Δ/L) of the pinned elastica, maths notes §5.3.
const ELASTICA: [(f64, f64, f64); 8] = [
    (5.0, 1.00095, 0.00190),
    (10.0, 1.00382, 0.00760),
    (20.0, 1.01540, 0.03027),
    (30.0, 1.03512, 0.06757),
    (45.0, 1.08154, 0.14934),
    (60.0, 1.15172, 0.25898),
    (90.0, 1.39320, 0.54305),
    (120.0, 1.88480, 0.87684),
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let b = 1e-5;
    let fabric = FabricParameters {
        bend_warp: b,
        bend_weft: b,
        stretch_warp: 1e4,
        stretch_weft: 1e4,
        ..FabricParameters::default()
    };
    let law: Arc<dyn MaterialLaw> = Arc::new(fabric.linear_law());
    let strip = Strip {
        law,
        length: 0.1,
        width: 0.01,
        cells: 60,
        ends: StripEnds::Pinned,
    };
    let pcr = strip.euler_load(b);
    let path = strip.compress(b, 0.6, 120)?;
    let sim: Vec<[f64; 2]> = path.iter().map(|p| [p.shortening, p.load / pcr]).collect();
    // one Choi–Ko connection of the strip's length and rigidity: chord shortening = Δ/L
    let (kb, l) = (b * strip.width, strip.length);
    let euler = std::f64::consts::PI.powi(2) * kb / (l * l);
    let ck: Vec<[f64; 2]> = (0..=120)
        .map(|k| {
            let s = 0.6 * k as f64 / 120.0;
            [s, -buckling_force(kb, l, l * (1.0 - s).max(1e-9)).0 / euler]
        })
        .collect();
    let table: Vec<[f64; 2]> = ELASTICA.iter().map(|r| [r.2, r.1]).collect();
    for &(alpha, p, short) in &ELASTICA {
        if short > 0.6 {
            continue;
        }
        let k = path
            .iter()
            .position(|q| q.shortening >= short)
            .unwrap_or(path.len() - 1);
        let (q0, q1) = (&path[k.saturating_sub(1)], &path[k]);
        let t = if q1.shortening > q0.shortening {
            (short - q0.shortening) / (q1.shortening - q0.shortening)
        } else {
            0.0
        };
        let model = (q0.load + t * (q1.load - q0.load)) / pcr;
        let chk = -buckling_force(kb, l, l * (1.0 - short)).0 / euler;
        println!(
            "{{\"end_rotation_deg\":{alpha},\"shortening\":{short},\"elastica\":{p},\"bending_model\":{model:.5},\"bending_dev_pct\":{:.2},\"choi_ko\":{chk:.5},\"choi_ko_dev_pct\":{:.2}}}",
            (model / p - 1.0) * 100.0,
            (chk / p - 1.0) * 100.0
        );
    }
    let series = vec![
        Series {
            name: "bending lines, 60 cells (rig)".into(),
            points: sim,
            style: SeriesStyle::Solid,
        },
        Series {
            name: "Choi–Ko, one connection (arc kinematics)".into(),
            points: ck,
            style: SeriesStyle::Dashed,
        },
        Series {
            name: "pinned elastica (table)".into(),
            points: table,
            style: SeriesStyle::Markers,
        },
    ];
    let dir = Path::new("out/buckling");
    std::fs::create_dir_all(dir)?;
    write_series_csv(&dir.join("force_shortening.csv"), &series)?;
    let (png, _) = write_plot_pair(
        &dir.join("force_shortening"),
        &PlotSpec {
            title: "Compressed pinned strip: force against end shortening".into(),
            x_label: "end shortening Δ/L".into(),
            y_label: "P / P_cr".into(),
            series,
        },
    )?;
    println!("wrote {}", png.display());
    Ok(())
}
