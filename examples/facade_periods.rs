//! Floor height and tile width of each labelled street photo, from the mutual-information
//! repetition search on the whole (unrectified) photo, against the spacing of the labelled
//! window rows and columns: `cargo run --release --example facade_periods [DIR]`
//! (DIR defaults to `../shared/data/facades/labelmefacade`). A diagnostic of the first
//! analysis stage; prints one line per photo and the share within 10 %.
use std::path::PathBuf;

use emilion::facade::instances::window_instances;
use emilion::facade::repetition::{detect, Axis};
use emilion::facade::report::labelled_images;
use emilion::facade::structure::WindowGrid;
use emilion::facade::LabelMap;
use emilion::geometry::image::Gray;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../shared/data/facades/labelmefacade"));
    let (mut floors, mut tiles) = ((0, 0), (0, 0));
    let close = |gt: Option<f64>, p: Option<u32>, tally: &mut (u32, u32)| {
        if let Some(g) = gt {
            tally.1 += 1;
            if p.is_some_and(|p| (p as f64 - g).abs() <= 0.1 * g) {
                tally.0 += 1;
            }
        }
    };
    for name in labelled_images(&dir)? {
        let truth = LabelMap::read_labelmefacade(&dir.join("labels").join(format!("{name}.png")))?;
        let photo = Gray::read(&dir.join("images").join(format!("{name}.jpg")))?;
        let grid = WindowGrid::of(&window_instances(&truth));
        let t0 = std::time::Instant::now();
        let f = detect(&photo, Axis::Rows, photo.height / 25, photo.height / 2);
        let c = detect(&photo, Axis::Columns, photo.width / 25, photo.width / 2);
        let secs = t0.elapsed().as_secs_f64();
        let (fp, cp) = (f.map(|r| r.period), c.map(|r| r.period));
        close(grid.floor_height(), fp, &mut floors);
        close(grid.tile_width(), cp, &mut tiles);
        println!(
            "{name}: floor {fp:?} (labels {:?}), tile {cp:?} (labels {:?}), {secs:.2} s",
            grid.floor_height().map(f64::round),
            grid.tile_width().map(f64::round)
        );
    }
    println!(
        "floor height within 10 %: {}/{}; tile width within 10 %: {}/{}",
        floors.0, floors.1, tiles.0, tiles.1
    );
    Ok(())
}
