//! Script bindings of the synthetic multi-camera sequences: `track::make_sequence`.

use rhai::{Dynamic, Map, FLOAT, INT};

use super::convert::{rt_err, RResult};
use super::paths::{read_folder, read_path, write_folder};
use super::{function, modules::ApiBuilder};
use crate::tracking::sequence::{make_sequence, SequenceOptions, SequenceSummary};

/// Option keys of `track::make_sequence(motion, out, options)`.
const KEYS: [&str; 14] = [
    "cameras",
    "width",
    "height",
    "fps",
    "frames",
    "start",
    "noise",
    "lighting",
    "occluder",
    "seed",
    "backgrounds",
    "makehuman",
    "lbs",
    "shading",
];

/// A number from an integer, a float or a numeric string (values given with `--set` arrive as
/// strings).
pub(super) fn number(d: &Dynamic, what: &str) -> RResult<f64> {
    let v = if let Some(f) = d.clone().try_cast::<FLOAT>() {
        Some(f)
    } else if let Some(i) = d.clone().try_cast::<INT>() {
        Some(i as f64)
    } else if d.is_string() {
        d.clone()
            .into_string()
            .ok()
            .and_then(|s| s.trim().parse::<f64>().ok())
    } else {
        None
    };
    match v {
        Some(v) if v.is_finite() => Ok(v),
        _ => Err(rt_err(format!("`{what}` must be a finite number, got {d}"))),
    }
}

/// A non-negative integer from a number or a numeric string.
pub(super) fn whole(d: &Dynamic, what: &str) -> RResult<u64> {
    let v = number(d, what)?;
    if v < 0.0 || v.fract() != 0.0 || v > 1e15 {
        return Err(rt_err(format!(
            "`{what}` must be a non-negative integer, got {d}"
        )));
    }
    Ok(v as u64)
}

/// A boolean from `true`/`false` or the strings "true"/"false".
pub(super) fn flag(d: &Dynamic, what: &str) -> RResult<bool> {
    if let Ok(b) = d.as_bool() {
        return Ok(b);
    }
    match d.clone().into_string().ok().as_deref() {
        Some("true") => Ok(true),
        Some("false") => Ok(false),
        _ => Err(rt_err(format!("`{what}` must be true or false, got {d}"))),
    }
}

/// Sequence options from a script map (unknown keys are errors listing the known ones).
fn options(m: &Map) -> RResult<SequenceOptions> {
    let mut o = SequenceOptions::default();
    apply_options(&mut o, m, "make_sequence", &[])?;
    o.validate().map_err(rt_err)?;
    Ok(o)
}

/// Sets the fields of `o` named in `m` (the keys of [`KEYS`]; keys in `skip` are left to the
/// caller); an unknown key is an error naming `function` and the known keys.
pub(super) fn apply_options(
    o: &mut SequenceOptions,
    m: &Map,
    function: &str,
    skip: &[&str],
) -> RResult<()> {
    for (k, v) in m {
        let k = k.as_str();
        match k {
            "cameras" => o.cameras = whole(v, k)? as usize,
            "width" => {
                o.width = u32::try_from(whole(v, k)?).map_err(|_| rt_err("`width` is too large"))?
            }
            "height" => {
                o.height =
                    u32::try_from(whole(v, k)?).map_err(|_| rt_err("`height` is too large"))?
            }
            "fps" => o.fps = number(v, k)?,
            "frames" => {
                o.frames = if v.is_unit() {
                    None
                } else {
                    Some(whole(v, k)? as usize)
                }
            }
            "start" => o.start_time = number(v, k)?,
            "noise" => o.noise_sigma = number(v, k)?,
            "lighting" => o.lighting_amplitude = number(v, k)?,
            "occluder" => o.occluder_fraction = number(v, k)?,
            "seed" => o.seed = whole(v, k)?,
            "lbs" => o.lbs = flag(v, k)?,
            "shading" => o.shading = flag(v, k)?,
            "backgrounds" | "makehuman" => {
                let s = v
                    .clone()
                    .into_string()
                    .map_err(|t| rt_err(format!("`{k}` must be a folder path, got {t}")))?;
                if k == "backgrounds" {
                    o.backgrounds = read_folder(&s)?;
                } else {
                    o.makehuman = read_folder(&s)?;
                }
            }
            other if skip.contains(&other) => {}
            other => {
                return Err(rt_err(format!(
                    "{function}: unknown option `{other}` (known: {})",
                    KEYS.iter()
                        .chain(skip)
                        .copied()
                        .collect::<Vec<_>>()
                        .join(", ")
                )))
            }
        }
    }
    Ok(())
}

/// The summary as a script map.
fn summary_map(s: &SequenceSummary) -> Map {
    let mut m = Map::new();
    m.insert("frames".into(), Dynamic::from_int(s.frames as INT));
    m.insert("cameras".into(), Dynamic::from_int(s.cameras as INT));
    m.insert("width".into(), Dynamic::from_int(s.width as INT));
    m.insert("height".into(), Dynamic::from_int(s.height as INT));
    m.insert("seconds".into(), Dynamic::from_float(s.seconds));
    m.insert(
        "seconds_per_frame".into(),
        Dynamic::from_float(s.seconds_per_frame),
    );
    m.insert("dir".into(), s.dir.display().to_string().into());
    m
}

fn run(motion: &str, out: &str, o: &SequenceOptions) -> RResult<Map> {
    let s = make_sequence(&read_path(motion)?, &write_folder(out)?, o).map_err(rt_err)?;
    Ok(summary_map(&s))
}

/// Registers `track::make_sequence`.
pub fn register(engine: &mut ApiBuilder) {
    function!(
        engine,
        "track::make_sequence",
        alias = "make_sequence",
        ["motion: String", "out: String", "Map"],
        "Makes a synthetic multi-camera sequence of a BVH clip into folder `out`: the MakeHuman
mannequin in clothes-like colours, on a treadmill, filmed by 4 cameras on a ring (320×240,
50 fps, the whole clip) in front of real photos, with a static occluder over 10% of each
image, changing light and sensor noise. Writes `sequence.json`, `cameras/camN.json`,
`images/camN/kkkk.png`, `ground_truth.csv` (16 joints per frame) and `init_joints.csv`.
Returns #{frames, cameras, width, height, seconds, seconds_per_frame, dir}.",
        |motion: &str, out: &str| run(motion, out, &SequenceOptions::default())
    );
    function!(
        engine,
        "track::make_sequence",
        alias = "make_sequence",
        ["motion: String", "out: String", "options: Map", "Map"],
        "As `track::make_sequence(motion, out)` with options (numbers may be given as strings):
`cameras` (1–64), `width`, `height` (pixels), `fps`, `frames` (default: the whole clip),
`start` (clip time of frame 0, s), `noise` (Gaussian sigma, grey levels, default 4),
`lighting` (amplitude of the light changes, default 0.15), `occluder` (fraction of each
image covered, default 0.1; 0 = none), `seed`, `backgrounds` (folder of photos), `makehuman`
(MakeHuman data folder), `lbs` (false: rigid skinning by dominant bone), `shading`.",
        |motion: &str, out: &str, m: Map| run(motion, out, &options(&m)?)
    );
}
