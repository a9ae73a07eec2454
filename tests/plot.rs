//! Plot output tests: PNG and SVG files of a hysteresis loop against a straight line open,
//! have the requested size and show every series; the CSV holds every point; awkward data
//! (empty series, NaN, one point, constant values) plots without panicking; failures name
//! the file and leave no temporary files behind.

use std::path::{Path, PathBuf};

use emilion::render::plot::{series_colour, PAIR_SIZE};
use emilion::render::{
    write_plot, write_plot_pair, write_series_csv, PlotSpec, Series, SeriesStyle,
};

/// A fresh, empty folder under the target's test temp dir.
fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("plot")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Names of the files in `dir`.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A KES-B-like bending hysteresis loop: moment against curvature, up along the upper
/// branch, back along the lower one (`n` points per branch).
fn loop_points(n: usize) -> Vec<[f64; 2]> {
    let branch = |k: f64, up: bool| {
        let h = if up { -0.3 } else { 0.3 };
        1.2 * k + h * (1.0 - (-4.0 * (k + 2.5).min(2.5 - k)).exp())
    };
    let up = (0..n).map(|i| -2.5 + 5.0 * i as f64 / (n - 1) as f64);
    let down = (0..n).map(|i| 2.5 - 5.0 * i as f64 / (n - 1) as f64);
    up.map(|k| [k, branch(k, false)])
        .chain(down.map(|k| [k, branch(k, true)]))
        .collect()
}

fn loop_spec() -> PlotSpec {
    PlotSpec {
        title: "fabric N1 — bending_warp".into(),
        x_label: "curvature (1/cm)".into(),
        y_label: "moment (gf·cm/cm)".into(),
        series: vec![
            Series {
                name: "measured".into(),
                points: loop_points(25),
                style: SeriesStyle::Markers,
            },
            Series {
                name: "simulated (fine mesh)".into(),
                points: loop_points(200)
                    .iter()
                    .map(|p| [p[0], 1.05 * p[1]])
                    .collect(),
                style: SeriesStyle::Solid,
            },
            Series {
                name: "linear fit".into(),
                points: vec![[-2.5, -3.0], [2.5, 3.0]],
                style: SeriesStyle::Dashed,
            },
        ],
    }
}

/// How many pixels of `image` have exactly the colour `rgb`.
fn count(image: &image::RgbImage, rgb: [u8; 3]) -> usize {
    image.pixels().filter(|p| p.0 == rgb).count()
}

#[test]
fn png_has_the_size_and_shows_every_series() {
    let dir = temp_dir("png");
    let spec = loop_spec();
    let (png, svg) = write_plot_pair(&dir.join("loop"), &spec).unwrap();
    assert_eq!(png, dir.join("loop.png"));
    assert_eq!(svg, dir.join("loop.svg"));
    assert_eq!(
        listing(&dir),
        ["loop.png", "loop.svg"],
        "no temporary files left"
    );

    let image = image::open(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), PAIR_SIZE);
    let white = count(&image, [255, 255, 255]);
    let total = image.len() / 3;
    assert!(white < total, "the picture is blank");
    assert!(white > total / 2, "the background is white");
    for k in 0..spec.series.len() {
        let n = count(&image, series_colour(k));
        assert!(
            n > 100,
            "series {k} ({}) has {n} pixels",
            spec.series[k].name
        );
    }
    // dark pixels: text, axes and the legend border
    let dark = image
        .pixels()
        .filter(|p| p.0.iter().all(|&c| c < 64))
        .count();
    assert!(dark > 500, "{dark} dark pixels: text and axes missing?");

    // another size
    let small = dir.join("small.PNG");
    write_plot(&small, &spec, 320, 200).unwrap();
    let image = image::open(&small).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (320, 200));
    assert!(count(&image, series_colour(1)) > 20);
}

#[test]
fn svg_holds_the_text() {
    let dir = temp_dir("svg");
    let mut spec = loop_spec();
    spec.series[2].name = "fit <a & b>".into();
    let path = dir.join("loop.svg");
    write_plot(&path, &spec, 640, 480).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("<svg"), "{}", &text[..text.len().min(200)]);
    assert!(text.trim_end().ends_with("</svg>"));
    for needle in [
        "measured",
        "simulated (fine mesh)",
        "fit &lt;a &amp; b&gt;",
        "curvature (1/cm)",
        "moment (gf·cm/cm)",
        "fabric N1 — bending_warp",
    ] {
        assert!(text.contains(needle), "SVG lacks {needle:?}");
    }
    for k in 0..3 {
        let [r, g, b] = series_colour(k);
        let hex = format!("#{r:02X}{g:02X}{b:02X}");
        assert!(
            text.to_uppercase().contains(&hex),
            "SVG lacks colour {hex} of series {k}"
        );
    }
}

#[test]
fn csv_has_a_row_per_point() {
    let dir = temp_dir("csv");
    let mut series = loop_spec().series;
    series.push(Series {
        name: "odd, \"name\"".into(),
        points: vec![[1.0, f64::NAN], [0.1, -2.5e-7]],
        style: SeriesStyle::Markers,
    });
    series.push(Series {
        name: "empty".into(),
        points: vec![],
        style: SeriesStyle::Solid,
    });
    let path = dir.join("loop.csv");
    write_series_csv(&path, &series).unwrap();
    assert_eq!(listing(&dir), ["loop.csv"]);
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "series,x,y");
    let points: usize = series.iter().map(|s| s.points.len()).sum();
    assert_eq!(lines.len(), 1 + points);
    assert_eq!(
        lines.iter().filter(|l| l.starts_with("measured,")).count(),
        50
    );
    assert_eq!(
        lines
            .iter()
            .filter(|l| l.starts_with("linear fit,"))
            .count(),
        2
    );
    assert_eq!(lines[1 + 50 + 400], "linear fit,-2.5,-3");
    assert_eq!(lines[points - 1], "\"odd, \"\"name\"\"\",1,NaN");
    assert_eq!(lines[points], "\"odd, \"\"name\"\"\",0.1,-0.00000025");
    // numbers read back exactly
    let first: Vec<&str> = lines[1].split(',').collect();
    let p = series[0].points[0];
    assert_eq!(first[1].parse::<f64>().unwrap(), p[0]);
    assert_eq!(first[2].parse::<f64>().unwrap(), p[1]);
}

#[test]
fn awkward_data_plots_without_panicking() {
    let dir = temp_dir("awkward");
    let series = |name: &str, points: Vec<[f64; 2]>, style| Series {
        name: name.into(),
        points,
        style,
    };
    let specs = [
        ("no_series", vec![]),
        (
            "empty_series",
            vec![
                series("nothing", vec![], SeriesStyle::Solid),
                series("nothing either", vec![], SeriesStyle::Markers),
            ],
        ),
        (
            "nan",
            vec![
                series(
                    "holes",
                    vec![
                        [0.0, 0.0],
                        [1.0, f64::NAN],
                        [2.0, 1.0],
                        [3.0, 2.0],
                        [f64::INFINITY, 0.0],
                        [5.0, 1.0],
                    ],
                    SeriesStyle::Solid,
                ),
                series(
                    "all nan",
                    vec![[f64::NAN, f64::NAN]; 4],
                    SeriesStyle::Dashed,
                ),
                series("one point", vec![[2.5, 1.5]], SeriesStyle::Dashed),
            ],
        ),
        (
            "constant",
            vec![series(
                "flat",
                vec![[1.0, 7.0], [1.0, 7.0]],
                SeriesStyle::Solid,
            )],
        ),
        (
            "tiny_and_huge",
            vec![
                series(
                    "tiny",
                    vec![[0.0, 1e-12], [1e-9, 3e-12]],
                    SeriesStyle::Markers,
                ),
                series(
                    "huge",
                    vec![[0.0, 1e300], [1e-9, -1e300]],
                    SeriesStyle::Solid,
                ),
            ],
        ),
    ];
    for (name, series) in specs {
        let spec = PlotSpec {
            title: name.into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series,
        };
        let (png, svg) =
            write_plot_pair(&dir.join(name), &spec).unwrap_or_else(|e| panic!("{name}: {e}"));
        let image = image::open(&png).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), PAIR_SIZE, "{name}");
        assert!(
            count(&image, [255, 255, 255]) < image.len() / 3,
            "{name}: blank"
        );
        assert!(
            std::fs::read_to_string(&svg).unwrap().contains("<svg"),
            "{name}"
        );
    }
    // the segments either side of a NaN are drawn; the lone point too
    let image = image::open(dir.join("nan.png")).unwrap().to_rgb8();
    assert!(count(&image, series_colour(0)) > 100);
    assert!(count(&image, series_colour(2)) > 5);
}

#[test]
fn stems_keep_their_dots() {
    let dir = temp_dir("stem");
    let (png, svg) = write_plot_pair(&dir.join("N1.2_shear"), &loop_spec()).unwrap();
    assert_eq!(png, dir.join("N1.2_shear.png"));
    assert_eq!(svg, dir.join("N1.2_shear.svg"));
    assert!(png.is_file() && svg.is_file());
}

#[test]
fn failures_name_the_path() {
    let dir = temp_dir("errors");
    let spec = loop_spec();
    let missing = dir.join("no_such_dir");
    for file in ["plot.png", "plot.svg", "plot.csv"] {
        let path = missing.join(file);
        let err = if file.ends_with(".csv") {
            write_series_csv(&path, &spec.series)
        } else {
            write_plot(&path, &spec, 400, 300)
        }
        .unwrap_err();
        assert_eq!(err.path, path);
        let message = err.to_string();
        assert!(message.contains(&path.display().to_string()), "{message}");
    }
    let err = write_plot_pair(&missing.join("pair"), &spec).unwrap_err();
    assert!(err.to_string().contains("pair.png"), "{err}");

    // a target that cannot be replaced: the temporary file is cleaned up
    let occupied = dir.join("occupied.png");
    std::fs::create_dir(&occupied).unwrap();
    std::fs::write(occupied.join("keep"), "x").unwrap();
    let err = write_plot(&occupied, &spec, 400, 300).unwrap_err();
    assert!(err.to_string().contains("occupied.png"), "{err}");
    assert_eq!(listing(&dir), ["occupied.png"]);

    // bad requests
    let err = write_plot(&dir.join("plot.jpg"), &spec, 400, 300).unwrap_err();
    assert!(
        err.to_string().contains("plot.jpg") && err.to_string().contains(".png"),
        "{err}"
    );
    let err = write_plot(&dir.join("plot"), &spec, 400, 300).unwrap_err();
    assert!(err.to_string().contains("plot"), "{err}");
    for (w, h) in [(0, 300), (400, 0), (10, 10), (100_000, 300)] {
        let err = write_plot(&dir.join("size.png"), &spec, w, h).unwrap_err();
        assert!(err.to_string().contains("size.png"), "{err}");
    }
    assert_eq!(listing(&dir), ["occupied.png"]);
}

#[test]
fn palette_colours_are_distinct() {
    let colours: Vec<[u8; 3]> = (0..10).map(series_colour).collect();
    for i in 0..10 {
        assert_ne!(colours[i], [255, 255, 255]);
        assert_ne!(colours[i], [0, 0, 0]);
        for j in 0..i {
            assert_ne!(colours[i], colours[j], "series {i} and {j}");
        }
    }
    assert_eq!(series_colour(10), series_colour(0));
}
