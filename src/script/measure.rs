//! Script bindings that measure a cloth (compressed springs, wrinkles along a line) and plot
//! series the script collected (PNG, SVG and CSV).

use rhai::{Array, Dynamic, Map, INT};

use super::convert::{finite, index, non_negative, rt_err, RResult};
use super::paths::write_path;
use super::{function, modules::ApiBuilder, register, SimHandle};
use crate::cloth::buckling::wrinkles::{compressed_springs, energy_parts, wrinkles_along};
use crate::geometry::Vec3;
use crate::render::plot::{write_plot_pair, write_series_csv, PlotSpec, Series, SeriesStyle};

/// Numbers of a script array, named for errors.
fn floats(a: &Dynamic, what: &str) -> RResult<Vec<f64>> {
    let arr = a
        .clone()
        .try_cast::<Array>()
        .ok_or_else(|| rt_err(format!("`{what}` must be an array of numbers")))?;
    arr.iter()
        .enumerate()
        .map(|(k, v)| finite(v, &format!("{what}[{k}]")))
        .collect()
}

/// Registers the measuring and plotting functions.
pub fn register(engine: &mut ApiBuilder) {
    register!(engine, "compression", ["sim: Simulation", "strain: float", "Map"],
        "Stretch springs compressed by more than `strain` (e.g. 0.01) now: #{springs, compressed,\nfraction}. A cloth without a buckling model pushed in its plane stays compressed.",
        |h: &mut SimHandle, strain: Dynamic| -> RResult<Map> {
            let strain = non_negative(&strain, "strain")?;
            let sim = h.get()?;
            let c = compressed_springs(&sim.model, &sim.state.x, strain);
            let mut m = Map::new();
            m.insert("springs".into(), Dynamic::from_int(c.springs as INT));
            m.insert("compressed".into(), Dynamic::from_int(c.compressed as INT));
            m.insert("fraction".into(), Dynamic::from_float(c.fraction()));
            Ok(m)
        });
    register!(engine, "energy_parts", ["sim: Simulation", "Map"],
        "The elastic energy now, split by what stores it (J): #{stretch, shear, bending, flexion\n(Choi–Ko's buckled connections), total}.",
        |h: &mut SimHandle| -> RResult<Map> {
            let sim = h.get()?;
            let e = energy_parts(&sim.model, &sim.state.x);
            let mut m = Map::new();
            for (k, v) in [
                ("stretch", e.stretch),
                ("shear", e.shear),
                ("bending", e.bending),
                ("flexion", e.flexion),
                ("total", e.total()),
            ] {
                m.insert(k.into(), Dynamic::from_float(v));
            }
            Ok(m)
        });
    register!(engine, "wrinkles", ["sim: Simulation", "line: Array", "threshold: float", "Map"],
        "Wrinkles along the particles `line` (in order), heights along z: #{half_waves, wavelength\n(m, twice the line's span over the half-waves), amplitude (m)}. Deviations from the mean\nheight smaller than `threshold` (m) do not count.",
        |h: &mut SimHandle, line: Array, threshold: Dynamic| -> RResult<Map> {
            let threshold = non_negative(&threshold, "threshold")?;
            let sim = h.get()?;
            let n = sim.state.x.len();
            let ids = line
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let i = index(v.as_int().map_err(|_| rt_err(format!("line[{k}] must be an int")))?, "particle")?;
                    if i >= n {
                        return Err(rt_err(format!("line[{k}] = {i} is out of range (cloth has {n})")));
                    }
                    Ok(i)
                })
                .collect::<RResult<Vec<usize>>>()?;
            let w = wrinkles_along(&sim.state.x, &ids, Vec3::z(), threshold);
            let mut m = Map::new();
            m.insert("half_waves".into(), Dynamic::from_int(w.half_waves as INT));
            m.insert("wavelength".into(), Dynamic::from_float(w.wavelength));
            m.insert("amplitude".into(), Dynamic::from_float(w.amplitude));
            Ok(m)
        });
    function!(engine, "plot::lines", alias = "plot", ["stem: String", "spec: Map", "Array"],
        "Writes a line plot as `stem`.png, `stem`.svg and `stem`.csv from\n#{title, x_label, y_label, series: [#{name, x: [..], y: [..], style: \"solid\" | \"dashed\" |\n\"markers\"}]}; returns the paths written.",
        |stem: &str, spec: Map| -> RResult<Array> {
            let text = |k: &str| -> RResult<String> {
                spec.get(k)
                    .map(|v| v.to_string())
                    .ok_or_else(|| rt_err(format!("plot: the spec needs `{k}`")))
            };
            let list = spec
                .get("series")
                .and_then(|s| s.clone().try_cast::<Array>())
                .ok_or_else(|| rt_err("plot: `series` must be an array of maps"))?;
            let mut series = Vec::new();
            for (k, s) in list.iter().enumerate() {
                let s = s
                    .clone()
                    .try_cast::<Map>()
                    .ok_or_else(|| rt_err(format!("plot: series[{k}] must be a map")))?;
                let get = |f: &str| {
                    s.get(f)
                        .ok_or_else(|| rt_err(format!("plot: series[{k}] needs `{f}`")))
                };
                let (x, y) = (floats(get("x")?, "x")?, floats(get("y")?, "y")?);
                if x.len() != y.len() {
                    return Err(rt_err(format!(
                        "plot: series[{k}] has {} x and {} y values",
                        x.len(),
                        y.len()
                    )));
                }
                let style = match s.get("style").map(|v| v.to_string()).as_deref() {
                    None | Some("solid") => SeriesStyle::Solid,
                    Some("dashed") => SeriesStyle::Dashed,
                    Some("markers") => SeriesStyle::Markers,
                    Some(other) => {
                        return Err(rt_err(format!(
                            "plot: series[{k}] style `{other}` (solid, dashed, markers)"
                        )))
                    }
                };
                series.push(Series {
                    name: get("name")?.to_string(),
                    points: x.into_iter().zip(y).map(|(a, b)| [a, b]).collect(),
                    style,
                });
            }
            let stem = write_path(stem)?;
            if let Some(d) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(d).map_err(|e| rt_err(format!("{}: {e}", d.display())))?;
            }
            let csv = stem.with_extension("csv");
            write_series_csv(&csv, &series).map_err(|e| rt_err(e.to_string()))?;
            let spec = PlotSpec {
                title: text("title")?,
                x_label: text("x_label")?,
                y_label: text("y_label")?,
                series,
            };
            let (png, svg) = write_plot_pair(&stem, &spec).map_err(|e| rt_err(e.to_string()))?;
            Ok([png, svg, csv]
                .iter()
                .map(|p| Dynamic::from(p.display().to_string()))
                .collect())
        });
}
