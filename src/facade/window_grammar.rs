//! The grammar of a facade whose windows were found one by one
//! ([`super::window_blobs`]), by recursive XY cuts: the facade is split top to bottom into
//! wall and rows of windows (groups that overlap vertically; rules `RowN`, `split(x)`), each
//! row left to right into wall and stacks (groups that overlap horizontally; rules `StackN`,
//! `split(y)`), and so on until a part is one window or wall. Windows keep their size
//! (fixed parts), the wall between them floats, so the rules regenerate the parse exactly at
//! the photo's size and spread or squeeze the windows at other sizes. Identical parts share
//! one rule.

use std::collections::BTreeMap;

use super::grammar::{Body, Dir, Grammar, Size};
use super::labels::Class;
use super::rect::Rect;
use super::refinement::{framed_window, named, Refinement};
use super::structure::root;

/// The extent of `r` along `dir`.
fn span(r: &Rect, dir: Dir) -> (u32, u32) {
    match dir {
        Dir::X => (r.x0, r.x1),
        Dir::Y => (r.y0, r.y1),
    }
}

/// The windows grouped by their projection on `dir`: groups whose extents do not overlap, in
/// order, each with its extent.
fn groups(windows: &[Rect], dir: Dir) -> Vec<((u32, u32), Vec<Rect>)> {
    let mut sorted = windows.to_vec();
    sorted.sort_by_key(|r| (span(r, dir), r.x0, r.y0, r.x1, r.y1));
    let mut out: Vec<((u32, u32), Vec<Rect>)> = Vec::new();
    for r in sorted {
        let (a, b) = span(&r, dir);
        match out.last_mut() {
            Some(((_, end), members)) if a < *end => {
                *end = (*end).max(b);
                members.push(r);
            }
            _ => out.push(((a, b), vec![r])),
        }
    }
    out
}

/// A split along `dir` of `[a, b)` into floating wall and fixed parts at `items` (start, end,
/// rule), zero-length walls left out.
fn split_between(dir: Dir, a: u32, b: u32, items: &[(u32, u32, String)]) -> Body {
    let mut parts = Vec::new();
    let mut at = a;
    for (s, e, rule) in items {
        if *s > at {
            parts.push((Size::Floating((s - at) as f64), "Wall".to_string()));
        }
        parts.push((Size::Fixed((e - s) as f64), rule.clone()));
        at = *e;
    }
    if b > at {
        parts.push((Size::Floating((b - at) as f64), "Wall".to_string()));
    }
    Body::Split { dir, parts }
}

/// The rule for `scope` holding `windows` (each inside it; a window here is the unit of a
/// window with its frame and sill, and `leaf` gives the rule of a unit): wall, the unit
/// filling it, or a cut across the scope between windows: rows first, then columns
/// (recursive XY cut). When no cut separates them (windows that overlap, or four that wind
/// round each other), the smallest is dropped.
fn rule_of(
    rules: &mut BTreeMap<String, Body>,
    scope: Rect,
    windows: &[Rect],
    leaf: &dyn Fn(&mut BTreeMap<String, Body>, &Rect) -> String,
) -> String {
    match windows {
        [] => return "Wall".into(),
        [w] if *w == scope => return leaf(rules, w),
        _ => {}
    }
    for (dir, base) in [(Dir::Y, "Stack"), (Dir::X, "Row")] {
        let g = groups(windows, dir);
        let (a, b) = span(&scope, dir);
        if g.len() == 1 && g[0].0 == (a, b) {
            continue;
        }
        let items: Vec<(u32, u32, String)> = g
            .into_iter()
            .map(|((s, e), members)| {
                let sub = match dir {
                    Dir::Y => Rect {
                        y0: s,
                        y1: e,
                        ..scope
                    },
                    Dir::X => Rect {
                        x0: s,
                        x1: e,
                        ..scope
                    },
                };
                (s, e, rule_of(rules, sub, &members, leaf))
            })
            .collect();
        let body = split_between(dir, a, b, &items);
        return named(rules, body, base);
    }
    let smallest = (0..windows.len())
        .min_by_key(|&i| (windows[i].area(), i))
        .unwrap_or(0);
    let rest: Vec<Rect> = windows
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != smallest)
        .map(|(_, r)| *r)
        .collect();
    rule_of(rules, scope, &rest, leaf)
}

/// The grammar of a `width` × `height` facade with `windows` (photo pixels, clipped to it)
/// and wall elsewhere. The windows of each size ([`SAME_SIZE`]) get the frame and sill that
/// `refine` finds round them (tile refinement synchronised over the windows of that size:
/// Müller's local synchronisation; `|_| Refinement::default()` for none): their sides move
/// as it says, and the frame and sill are added where they fit (inside the facade, clear of
/// the other windows and their frames); the others stay bare.
pub fn grammar_of_windows(
    windows: &[Rect],
    width: u32,
    height: u32,
    refine: &dyn Fn(&[Rect]) -> Refinement,
) -> Grammar {
    let mut rules = BTreeMap::new();
    rules.insert("Wall".to_string(), Body::Leaf(Class::Wall));
    let clipped: Vec<Rect> = windows
        .iter()
        .map(|r| Rect {
            x0: r.x0.min(width),
            y0: r.y0.min(height),
            x1: r.x1.min(width),
            y1: r.y1.min(height),
        })
        .filter(|r| r.area() > 0)
        .collect();
    // one refinement per size, measured on that size's windows
    let sizes = size_groups(&clipped);
    let per_size: Vec<Refinement> = (0..=sizes.iter().copied().max().unwrap_or(0))
        .map(|g| {
            let mine: Vec<Rect> = (0..clipped.len())
                .filter(|&k| sizes[k] == g)
                .map(|k| clipped[k])
                .collect();
            refine(&mine)
        })
        .collect();
    let refinements: Vec<Refinement> = sizes.iter().map(|&g| per_size[g]).collect();
    let inside: Vec<Rect> = clipped
        .iter()
        .zip(&refinements)
        .map(|(r, k)| {
            let w = k.window(r);
            Rect {
                x1: w.x1.min(width),
                y1: w.y1.min(height),
                ..w
            }
        })
        .collect();
    let full = Rect {
        x0: 0,
        y0: 0,
        x1: width,
        y1: height,
    };
    let units = units_of(&inside, &refinements, width, height);
    let leaf = |rules: &mut BTreeMap<String, Body>, u: &Rect| {
        let k = units.iter().position(|(unit, _)| unit == u);
        let name = window_rule(k.map_or(0, |k| sizes[k]));
        rules
            .entry(name.clone())
            .or_insert(Body::Leaf(Class::Window));
        match k.map(|k| (units[k].1, *u, refinements[k])) {
            Some((w, u, r)) if w != u => {
                framed_window(rules, r, (w.x1 - w.x0) as f64, (w.y1 - w.y0) as f64, &name)
            }
            _ => name,
        }
    };
    let unit_rects: Vec<Rect> = units.iter().map(|(u, _)| *u).collect();
    let top = rule_of(&mut rules, full, &unit_rects, &leaf);
    let facade = rules.get(&top).cloned().unwrap_or(Body::Leaf(Class::Wall));
    rules.insert("Facade".to_string(), facade);
    let used_elsewhere = rules.values().any(|b| match b {
        Body::Split { parts, .. } => parts.iter().any(|(_, r)| *r == top),
        Body::Repeat { rule, .. } => *rule == top,
        Body::Leaf(_) | Body::Insert { .. } => false,
    });
    if !matches!(rules.get(&top), Some(Body::Leaf(_))) && !used_elsewhere {
        rules.remove(&top);
    }
    Grammar {
        rules,
        axiom: "Facade".into(),
        size: (width as f64, height as f64),
    }
}

/// Windows whose widths and heights both differ by at most this share of the larger are of
/// one size (single linkage). Each size of at least [`MIN_GROUP`] windows has its own window
/// rule (`Window` for the size most windows have, and the sizes of fewer windows; then
/// `Window2`, …), so element recognition can give each its own element
/// ([`super::element_match::recognise_elements`], which merges the rules again where it
/// does not).
pub const SAME_SIZE: f64 = 0.15;

/// Fewest windows of one size for a rule (and a recognition) of their own.
pub const MIN_GROUP: usize = 3;

/// The rule of the windows of size group `k`.
fn window_rule(k: usize) -> String {
    if k == 0 {
        "Window".into()
    } else {
        format!("Window{}", k + 1)
    }
}

/// The size group of each window: groups by [`SAME_SIZE`], numbered from the one with most
/// windows (ties: the one whose first window comes first); windows of groups smaller than
/// [`MIN_GROUP`] are in group 0.
fn size_groups(windows: &[Rect]) -> Vec<usize> {
    let n = windows.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let close = |a: u32, b: u32| a.abs_diff(b) as f64 <= SAME_SIZE * a.max(b) as f64;
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (&windows[i], &windows[j]);
            if close(a.x1 - a.x0, b.x1 - b.x0) && close(a.y1 - a.y0, b.y1 - b.y0) {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    let roots: Vec<usize> = (0..n).map(|i| root(&mut parent, i)).collect();
    // (count, first window) of each group, most windows first
    let mut order: Vec<(usize, usize)> = (0..n)
        .filter(|&i| roots[i] == i)
        .map(|r| (roots.iter().filter(|&&q| q == r).count(), r))
        .collect();
    order.sort_by_key(|&(count, first)| (std::cmp::Reverse(count), first));
    // sizes of too few windows go with the most common one
    order.retain(|&(count, _)| count >= MIN_GROUP);
    roots
        .iter()
        .map(|r| order.iter().position(|o| o.1 == *r).unwrap_or(0))
        .collect()
}

/// Each window's unit (the window with its refinement's frame and sill) and the window: the
/// unit where it lies inside the `width` × `height` facade and clear of every other unit,
/// else the bare window (taking a frame back can only clear more room, so this settles).
fn units_of(
    windows: &[Rect],
    refinements: &[Refinement],
    width: u32,
    height: u32,
) -> Vec<(Rect, Rect)> {
    let mut units: Vec<(Rect, Rect)> = windows
        .iter()
        .zip(refinements)
        .map(|(w, r)| (r.unit(w), *w))
        .collect();
    loop {
        let mut changed = false;
        for i in 0..units.len() {
            let (u, w) = units[i];
            if u == w {
                continue;
            }
            let frame = refinements[i].frame;
            let outside = u.x1 > width || u.y1 > height || w.x0 < frame || w.y0 < frame;
            let overlaps = units
                .iter()
                .enumerate()
                .any(|(j, (v, _))| j != i && u.intersection(v) > 0);
            if outside || overlaps {
                units[i].0 = w;
                changed = true;
            }
        }
        if !changed {
            return units;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facade::rasterize::{rasterize, round_trip};

    #[test]
    fn the_rules_paint_the_windows_back_exactly() {
        // staggered rows and columns (no one band holds a whole row), and one window inside
        // another's extent that no cut can separate: it is dropped
        let windows = [
            Rect::new(10, 20, 30, 50),
            Rect::new(40, 25, 60, 50),
            Rect::new(70, 20, 90, 50),
            Rect::new(55, 30, 65, 45),
            Rect::new(10, 45, 30, 110),
            Rect::new(40, 60, 60, 90),
            Rect::new(70, 80, 90, 110),
        ];
        let g = grammar_of_windows(&windows, 100, 120, &|_| Refinement::default());
        let leaves = g.derive(100.0, 120.0).expect("derives");
        let parse = rasterize(&leaves, 100, 120);
        let mut got = parse.windows.clone();
        got.sort_by_key(|r| (r.y0, r.x0));
        let mut want: Vec<Rect> = windows
            .iter()
            .copied()
            .filter(|r| *r != Rect::new(55, 30, 65, 45))
            .collect();
        want.sort_by_key(|r| (r.y0, r.x0));
        // the window at 10..30 × 20..50 and the one below it overlap in rows 45..50: the
        // smaller of the two goes
        want.retain(|r| *r != Rect::new(10, 20, 30, 50));
        assert_eq!(got, want);
        assert_eq!(round_trip(&g, 100, 120).expect("round trip"), 1.0);
    }

    #[test]
    fn repeated_windows_share_their_rule() {
        let windows: Vec<Rect> = (0..3)
            .flat_map(|i| {
                (0..3).map(move |j| Rect::new(10 + 30 * j, 10 + 40 * i, 30 + 30 * j, 40 + 40 * i))
            })
            .collect();
        let g = grammar_of_windows(&windows, 100, 130, &|_| Refinement::default());
        // three identical rows: one rule for a row of windows
        let text = g.to_text();
        assert!(text.contains("Row1 --> split(x)"), "{text}");
        assert!(!text.contains("Row2"), "{text}");
        let parse = rasterize(&g.derive(100.0, 130.0).expect("derives"), 100, 130);
        assert_eq!(parse.windows.len(), 9);
    }

    #[test]
    fn resized_facades_keep_their_windows_apart() {
        let windows: Vec<Rect> = (0..4)
            .map(|j| Rect::new(10 + 30 * j, 10, 30 + 30 * j, 40))
            .collect();
        let g = grammar_of_windows(&windows, 130, 60, &|_| Refinement::default());
        for (w, h) in [(97.5, 45.0), (195.0, 90.0)] {
            let leaves = g.derive(w, h).expect("derives");
            let wins: Vec<_> = leaves.iter().filter(|l| l.class == Class::Window).collect();
            assert_eq!(wins.len(), 4);
            for p in wins.windows(2) {
                assert!(p[0].scope.x1 <= p[1].scope.x0 + 1e-9);
            }
        }
    }

    #[test]
    fn no_windows_is_plain_wall() {
        let g = grammar_of_windows(&[], 50, 40, &|_| Refinement::default());
        let leaves = g.derive(50.0, 40.0).expect("derives");
        assert_eq!(leaves.len(), 1);
        assert_eq!(leaves[0].class, Class::Wall);
    }
}
