//! The grammar of a parse ([`super::parse_structure::Structure`]): margins around the floors × tiles
//! layout; each floor a band of windows between wall above and below, the band cut into
//! cells that hold a window between wall (or plain wall where the cell has none), written as
//! split/repeat rules ([`super::grammar`]) that regenerate the parse exactly at the photo's
//! size and adapt to other sizes (floors and tiles repeat or stretch, windows keep their size).

use std::collections::BTreeMap;

use super::grammar::{Body, Dir, Grammar, Size};
use super::labels::Class;
use super::parse_structure::Structure;
use super::rect::Rect;
use super::refinement::{framed_window, Refinement};

/// A rule name for `key` among the variants seen so far: `base` for the first, `base2`, … for
/// the others.
fn variant<K: PartialEq>(seen: &mut Vec<K>, key: K, base: &str) -> String {
    let k = match seen.iter().position(|s| *s == key) {
        Some(k) => k,
        None => {
            seen.push(key);
            seen.len() - 1
        }
    };
    if k == 0 {
        base.to_string()
    } else {
        format!("{base}{}", k + 1)
    }
}

/// The grammar of a parse. Facade units are the photo's pixels. The window's sides move as
/// `refinement` says and it gets its frame and sill when they fit in every cell with wall to
/// spare; else it goes without them.
pub fn grammar_of(s: &Structure, width: u32, height: u32, refinement: Refinement) -> Grammar {
    let (w, h) = (width as f64, height as f64);
    let (fh, tw) = (s.floor as f64, s.tile as f64);
    let (nf, nt) = s.count;
    let (rs, cs) = (&s.row_starts, &s.col_starts);
    let mut rules = BTreeMap::new();
    let wall = || Body::Leaf(Class::Wall);
    rules.insert("Wall".to_string(), wall());
    let done = |rules| Grammar {
        rules,
        axiom: "Facade".into(),
        size: (w, h),
    };
    if nf == 0
        || nt == 0
        || rs.len() != nf + 1
        || cs.len() != nt + 1
        || !s.present.iter().any(|&p| p)
    {
        rules.insert("Facade".to_string(), wall());
        return done(rules);
    }
    let split = |dir: Dir, parts: Vec<(Size, String)>| Body::Split { dir, parts };
    let heights: Vec<f64> = rs.windows(2).map(|p| p[1] - p[0]).collect();
    let widths: Vec<f64> = cs.windows(2).map(|p| p[1] - p[0]).collect();
    let fits = |u: Rect| {
        u.x0 > 0
            && u.y0 > 0
            && widths.iter().all(|&wj| (u.x1 as f64) < wj)
            && heights.iter().all(|&hi| (u.y1 as f64) < hi)
    };
    // the moved window with its frame and sill if they fit, else without, else as found
    let refinement = [refinement, refinement.bare(), Refinement::default()]
        .into_iter()
        .find(|r| {
            let w = r.window(&s.window);
            w.x0 >= r.frame && w.y0 >= r.frame && fits(r.unit(&w))
        })
        .unwrap_or_default();
    let bare = refinement.window(&s.window);
    // the window with its frame and sill, and its rule
    let win = refinement.unit(&bare);
    let (win_w, win_h) = ((win.x1 - win.x0) as f64, (win.y1 - win.y0) as f64);
    let uniform_w = widths.iter().all(|&x| x == tw);
    rules.insert(
        "Facade".to_string(),
        split(
            Dir::Y,
            vec![
                (Size::Fixed(rs[0]), "Wall".into()),
                (Size::Floating(rs[nf] - rs[0]), "Floors".into()),
                (Size::Fixed(h - rs[nf]), "Wall".into()),
            ],
        ),
    );
    rules.insert("Window".to_string(), Body::Leaf(Class::Window));
    let unit = framed_window(
        &mut rules,
        refinement,
        (bare.x1 - bare.x0) as f64,
        (bare.y1 - bare.y0) as f64,
        "Window",
    );
    // one window-cell rule per distinct cell width: wall, the window, wall
    let mut tiles_seen: Vec<u64> = Vec::new();
    let tile_names: Vec<String> = widths
        .iter()
        .map(|&wj| {
            let name = variant(&mut tiles_seen, wj.to_bits(), "Tile");
            rules.entry(name.clone()).or_insert_with(|| {
                split(
                    Dir::X,
                    vec![
                        (Size::Floating(win.x0 as f64), "Wall".into()),
                        (Size::Fixed(win_w), unit.clone()),
                        (Size::Floating(wj - win.x1 as f64), "Wall".into()),
                    ],
                )
            });
            name
        })
        .collect();
    // one band rule per distinct pattern of cells with and without a window
    let mut rows_seen: Vec<&[bool]> = Vec::new();
    let mut floors_seen: Vec<(u64, String)> = Vec::new();
    let mut floor_names = Vec::with_capacity(nf);
    for (i, pattern) in s.present.chunks(nt).enumerate() {
        let band = if pattern.iter().all(|&p| !p) {
            None
        } else {
            let name = variant(&mut rows_seen, pattern, "Band");
            if !rules.contains_key(&name) {
                let cells = format!("{name}Cells");
                let cells_body = if uniform_w && pattern.iter().all(|&p| p) {
                    Body::Repeat {
                        dir: Dir::X,
                        size: tw,
                        rule: "Tile".into(),
                    }
                } else {
                    split(
                        Dir::X,
                        pattern
                            .iter()
                            .zip(&widths)
                            .zip(&tile_names)
                            .map(|((&p, &wj), t)| {
                                (
                                    Size::Floating(wj),
                                    if p { t.clone() } else { "Wall".into() },
                                )
                            })
                            .collect(),
                    )
                };
                rules.insert(cells.clone(), cells_body);
                rules.insert(
                    name.clone(),
                    split(
                        Dir::X,
                        vec![
                            (Size::Fixed(cs[0]), "Wall".into()),
                            (Size::Floating(cs[nt] - cs[0]), cells),
                            (Size::Fixed(w - cs[nt]), "Wall".into()),
                        ],
                    ),
                );
            }
            Some(name)
        };
        let floor = match band {
            None => "Wall".to_string(),
            Some(band) => {
                let hi = heights[i];
                let name = variant(&mut floors_seen, (hi.to_bits(), band.clone()), "Floor");
                rules.entry(name.clone()).or_insert_with(|| {
                    split(
                        Dir::Y,
                        vec![
                            (Size::Floating(win.y0 as f64), "Wall".into()),
                            (Size::Fixed(win_h), band),
                            (Size::Floating(hi - win.y1 as f64), "Wall".into()),
                        ],
                    )
                });
                name
            }
        };
        floor_names.push(floor);
    }
    let floors =
        if heights.iter().all(|&x| x == fh) && floor_names.iter().all(|n| n == &floor_names[0]) {
            Body::Repeat {
                dir: Dir::Y,
                size: fh,
                rule: floor_names[0].clone(),
            }
        } else {
            split(
                Dir::Y,
                floor_names
                    .into_iter()
                    .zip(&heights)
                    .map(|(n, &hi)| (Size::Floating(hi), n))
                    .collect(),
            )
        };
    rules.insert("Floors".to_string(), floors);
    done(rules)
}
