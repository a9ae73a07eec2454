//! Property tests (proptest) of the readers: what a writer writes, its reader reads back
//! exactly (OBJ, `.pts`, facade rule files), readers refuse arbitrary text with an error and
//! never panic, and the stated limits accept exactly the finite values within them. The
//! random-input fuzzing of every reader is the harness `examples/fuzz/` (docs/fuzzing.md).

use std::path::Path;

use emilion::facade::grammar::Grammar;
use emilion::geometry::obj::{obj_mesh_from_text, obj_surface_from_text};
use emilion::geometry::{grid_mesh, ExportFrame, Vec3};
use proptest::prelude::*;

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("emilion-fuzz-props-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    dir.join(name)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// A cloth written as OBJ (engine frame, rest coordinates) reads back with the same
    /// vertex order, positions, rest coordinates and triangles, bit for bit.
    #[test]
    fn obj_write_then_read_is_the_same_mesh(
        nx in 2usize..6,
        ny in 2usize..6,
        width in 0.05f64..3.0,
        height in 0.05f64..3.0,
        lift in proptest::collection::vec(-10.0f64..10.0, 36),
    ) {
        let grid = grid_mesh(width, height, nx, ny).expect("a grid");
        let positions: Vec<Vec3> = grid
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| Vec3::new(p.x, p.y, lift[i % lift.len()]))
            .collect();
        let path = scratch(&format!("grid_{nx}_{ny}.obj"));
        emilion::geometry::write_obj(
            &path,
            &positions,
            &grid.triangles,
            Some(&grid.rest),
            ExportFrame::ENGINE,
        )
        .expect("writing");
        let text = std::fs::read_to_string(&path).expect("reading back");
        let mesh = obj_mesh_from_text(&text, &path).expect("parsing back");
        prop_assert_eq!(mesh.triangles, grid.triangles);
        // Numbers are written in Rust's shortest round-trip form: read back exactly.
        prop_assert_eq!(mesh.positions, positions);
        prop_assert_eq!(mesh.rest, grid.rest);
    }

    /// The 68 iBUG landmarks written as `.pts` (3 decimals) read back within half a thousandth.
    #[test]
    fn pts_write_then_read_is_the_same_points(
        points in proptest::collection::vec((-5000.0f64..5000.0, -5000.0f64..5000.0), 68),
    ) {
        let points: Vec<[f64; 2]> = points.into_iter().map(|(x, y)| [x, y]).collect();
        let path = scratch(&format!("p{}.pts", points.len()));
        emilion::face::landmarks::write_pts(&path, &points).expect("writing");
        let back = emilion::face::landmarks::read_pts(&path).expect("reading back");
        prop_assert_eq!(back.len(), points.len());
        for (a, b) in back.iter().zip(&points) {
            prop_assert!((a[0] - b[0]).abs() <= 5e-4 + 1e-12 && (a[1] - b[1]).abs() <= 5e-4 + 1e-12);
        }
    }

    /// A rule file of repeats and splits, written by `to_text`, parses back to the same rules.
    #[test]
    fn facade_rules_to_text_then_parse_is_the_same_grammar(
        w in 50.0f64..2000.0,
        h in 50.0f64..2000.0,
        floor in 20.0f64..400.0,
        margin in 0.0f64..80.0,
        weight in 1u32..5,
    ) {
        let text = format!(
            "// axiom F size {w} {h}\nF --> split(y) {{ {margin}: W | ~{weight}: Fl }}\n\
             Fl --> repeat(y, {floor}) {{ T }}\nT --> insert(window, window_cross)\nW --> wall\n"
        );
        let g = Grammar::parse(&text).expect("parsing");
        let again = Grammar::parse(&g.to_text()).expect("parsing to_text");
        prop_assert_eq!(again, g);
    }

    /// Arbitrary text never makes the OBJ readers or the rule-file reader panic.
    #[test]
    fn arbitrary_text_is_refused_without_a_panic(text in "(v|vt|f|g|//|-->|[0-9 ./\\-\n{}|:~])*") {
        let p = Path::new("prop.obj");
        let _ = obj_mesh_from_text(&text, p);
        let _ = obj_surface_from_text(&text, p);
        let _ = Grammar::parse(&text).map(|g| g.derive(g.size.0, g.size.1));
    }

    /// `limits::check` accepts a value exactly when it is finite, not negative and within
    /// the limit, and then returns it as an integer.
    #[test]
    fn a_limit_accepts_exactly_the_finite_values_within_it(
        value in prop_oneof![any::<f64>(), -10.0f64..1e7],
        max in 0u64..1_000_000,
    ) {
        let r = emilion::limits::check("value", value, "max_elements", max);
        let within = value.is_finite() && value >= 0.0 && value <= max as f64;
        prop_assert_eq!(r.is_ok(), within);
        if let Ok(n) = r {
            prop_assert_eq!(n, value as u64);
        } else {
            prop_assert!(r.unwrap_err().to_string().contains("max_elements"));
        }
    }
}
