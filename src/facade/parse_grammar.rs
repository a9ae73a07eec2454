//! The grammar of a parse ([`super::parse::Structure`]): margins around the floors × tiles
//! layout, each cell holding the irreducible tile (a window with wall around it) or plain wall,
//! written as split/repeat rules ([`super::grammar`]) that regenerate the parse exactly at the
//! photo's size and adapt to other sizes (floors and tiles repeat, windows keep their size).

use super::grammar::{Body, Dir, Grammar, Size};
use super::labels::Class;
use super::parse::Structure;

/// The grammar of a parse: margins around the floors × tiles layout; in each cell either the
/// tile (a window with wall around it) or plain wall. Floors that all hold the tile repeat
/// along x; identical floors repeat along y; otherwise each floor pattern gets its own rule.
/// Facade units are the photo's pixels.
pub fn grammar_of(s: &Structure, width: u32, height: u32) -> Grammar {
    let (w, h) = (width as f64, height as f64);
    let (fh, tw) = (s.floor as f64, s.tile as f64);
    let (nf, nt) = s.count;
    let (left, top) = (s.origin.0 as f64, s.origin.1 as f64);
    let (floors_h, tiles_w) = (nf as f64 * fh, nt as f64 * tw);
    let (bottom, right) = (h - top - floors_h, w - left - tiles_w);
    let win = s.window;
    let (win_w, win_h) = ((win.x1 - win.x0) as f64, (win.y1 - win.y0) as f64);
    let leaf = |c: Class| Body::Leaf(c);
    let split = |dir: Dir, parts: Vec<(Size, String)>| Body::Split { dir, parts };
    let mut rules = std::collections::BTreeMap::new();
    rules.insert("Wall".to_string(), leaf(Class::Wall));
    let grammar = |rules| Grammar {
        rules,
        axiom: "Facade".into(),
        size: (w, h),
    };
    if nf == 0 || nt == 0 || !s.present.iter().any(|&p| p) {
        rules.insert("Facade".to_string(), leaf(Class::Wall));
        return grammar(rules);
    }
    rules.insert(
        "Facade".to_string(),
        split(
            Dir::Y,
            vec![
                (Size::Fixed(top), "Wall".into()),
                (Size::Floating(floors_h), "Floors".into()),
                (Size::Fixed(bottom), "Wall".into()),
            ],
        ),
    );
    // one rule per distinct floor pattern
    let patterns: Vec<&[bool]> = s.present.chunks(nt).collect();
    let mut names: Vec<String> = Vec::new();
    let mut seen: Vec<&[bool]> = Vec::new();
    for p in &patterns {
        let k = match seen.iter().position(|q| q == p) {
            Some(k) => k,
            None => {
                seen.push(p);
                seen.len() - 1
            }
        };
        let name = if p.iter().all(|&c| c) {
            "Floor".to_string()
        } else if p.iter().all(|&c| !c) {
            "Wall".to_string()
        } else {
            format!("Floor{k}")
        };
        names.push(name);
    }
    if names.iter().all(|n| n == &names[0]) {
        rules.insert(
            "Floors".to_string(),
            Body::Repeat {
                dir: Dir::Y,
                size: fh,
                rule: names[0].clone(),
            },
        );
    } else {
        rules.insert(
            "Floors".to_string(),
            split(
                Dir::Y,
                names
                    .iter()
                    .map(|n| (Size::Floating(fh), n.clone()))
                    .collect(),
            ),
        );
    }
    for (p, name) in patterns.iter().zip(&names) {
        if rules.contains_key(name) {
            continue;
        }
        let tiles = if p.iter().all(|&c| c) {
            rules.insert(
                "Tiles".to_string(),
                Body::Repeat {
                    dir: Dir::X,
                    size: tw,
                    rule: "Tile".into(),
                },
            );
            "Tiles".to_string()
        } else {
            let row = format!("{name}Cells");
            rules.insert(
                row.clone(),
                split(
                    Dir::X,
                    p.iter()
                        .map(|&c| (Size::Floating(tw), if c { "Tile" } else { "Wall" }.into()))
                        .collect(),
                ),
            );
            row
        };
        rules.insert(
            name.clone(),
            split(
                Dir::X,
                vec![
                    (Size::Fixed(left), "Wall".into()),
                    (Size::Floating(tiles_w), tiles),
                    (Size::Fixed(right), "Wall".into()),
                ],
            ),
        );
    }
    rules.insert(
        "Tile".to_string(),
        split(
            Dir::X,
            vec![
                (Size::Floating(win.x0 as f64), "Wall".into()),
                (Size::Fixed(win_w), "Column".into()),
                (Size::Floating(tw - win.x1 as f64), "Wall".into()),
            ],
        ),
    );
    rules.insert(
        "Column".to_string(),
        split(
            Dir::Y,
            vec![
                (Size::Floating(win.y0 as f64), "Wall".into()),
                (Size::Fixed(win_h), "Window".into()),
                (Size::Floating(fh - win.y1 as f64), "Wall".into()),
            ],
        ),
    );
    rules.insert("Window".to_string(), leaf(Class::Window));
    grammar(rules)
}
