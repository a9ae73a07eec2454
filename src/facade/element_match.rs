//! Element recognition (Müller et al. 2007 §4): which element of the library
//! ([`super::element_library`]) the windows (or doors) of a parse look like. Every instance is
//! resampled to a common grid and standardised (zero mean, unit deviation, so lighting and
//! contrast drop out), and the instances are averaged — as the irreducible tile, so curtains,
//! reflections and occluders of single windows average out. Only the inside of the opening is
//! compared (a margin of [`INNER`] is left out): where a frame lies against the detected
//! rectangle varies from photo to photo, while mullions, transoms and rails are what tells
//! window types apart. Each element's front view there (bars 1, glass 0, slightly blurred so
//! a bar a cell away still counts, and moved by up to an eighth of the height and a
//! twenty-fourth of the width, as transoms sit higher or lower from building to building) is a
//! one-regressor model of the mean window, both less their best plane (lighting that
//! brightens upper panes or shades lower ones); the element whose view explains most of its
//! variance (squared correlation) is chosen when that is at
//! least [`MIN_EXPLAINED`], and the plainest element of the class (the library's first, clear
//! inside) otherwise. Bars an element has and the photo lacks cost it as much as bars it
//! lacks, so a cross does not win on a window with a single mullion.

use super::element_library::Library;
use super::grammar::{Body, Grammar};
use super::labels::Class;
use super::rect::Rect;
use super::window_grammar::MIN_GROUP;
use crate::geometry::image::filters::box_mean_3x3;
use crate::geometry::image::Gray;

/// Side of the grid every instance is resampled to (even: its centre lies between cells).
pub const GRID: usize = 24;

/// Margin of the opening left out of the comparison (share of its width and height).
pub const INNER: f64 = 0.16;

/// Least share of the mean window's inner variance an element's bars must explain to be
/// chosen over the plainest element of the class.
pub const MIN_EXPLAINED: f64 = 0.15;

/// The element chosen for the instances of a class, and every candidate's score.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementMatch {
    /// The class of the instances.
    pub class: Class,
    /// The chosen element.
    pub element: String,
    /// (element, share of the mean window's variance its front view explains), library order.
    pub scores: Vec<(String, f64)>,
    /// How many instances were averaged.
    pub instances: usize,
    /// The rule whose instances these are when they are one size's only (`None`: all the
    /// instances of the class).
    pub rule: Option<String>,
}

impl ElementMatch {
    /// The share of variance the chosen element explains.
    pub fn explained(&self) -> f64 {
        self.scores
            .iter()
            .find(|s| s.0 == self.element)
            .map_or(0.0, |s| s.1)
    }
}

/// The instance in `r` (photo pixels) resampled bilinearly to `GRID` × `GRID` cell centres and
/// standardised; `None` when it is smaller than 3 pixels a side or flat.
pub fn normalised_instance(img: &Gray, r: &Rect) -> Option<Vec<f64>> {
    let (x1, y1) = (r.x1.min(img.width), r.y1.min(img.height));
    if x1 < r.x0 + 3 || y1 < r.y0 + 3 {
        return None;
    }
    let (w, h) = ((x1 - r.x0) as f64, (y1 - r.y0) as f64);
    let mut v = Vec::with_capacity(GRID * GRID);
    for j in 0..GRID {
        let y = r.y0 as f64 + (j as f64 + 0.5) / GRID as f64 * h - 0.5;
        for i in 0..GRID {
            let x = r.x0 as f64 + (i as f64 + 0.5) / GRID as f64 * w - 0.5;
            v.push(img.bilinear(x, y)?);
        }
    }
    standardise(&mut v).then_some(v)
}

/// Zero mean and unit deviation in place; false when `v` is flat.
fn standardise(v: &mut [f64]) -> bool {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    if var < 1e-6 {
        return false;
    }
    let sd = var.sqrt();
    v.iter_mut().for_each(|x| *x = (*x - mean) / sd);
    true
}

/// Shifts (columns, rows) of an element's view tried against the photo: transoms and rails sit
/// higher or lower from one building to the next (and the detected rectangle may include a
/// lintel or a sill), mullions stay near the middle.
const SHIFTS: [(isize, isize); 21] = {
    let mut s = [(0, 0); 21];
    let mut k = 0;
    while k < 21 {
        s[k] = ((k % 3) as isize - 1, (k / 3) as isize - 3);
        k += 1;
    }
    s
};

/// A `GRID` × `GRID` grid moved by `(dx, dy)` cells, edges repeated.
fn shifted(v: &[f64], (dx, dy): (isize, isize)) -> Vec<f64> {
    let n = GRID as isize;
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n - dx).clamp(0, n - 1), (k / n - dy).clamp(0, n - 1));
            v[(j * n + i) as usize]
        })
        .collect()
}

/// A `GRID` × `GRID` grid averaged over each cell's 3 × 3 neighbourhood (clamped at the
/// border).
fn blurred(v: Vec<f64>) -> Vec<f64> {
    let grid = Gray {
        width: GRID as u32,
        height: GRID as u32,
        data: v,
    };
    box_mean_3x3(&grid).data
}

/// Squared correlation of `a` and `b` (0 when either is flat).
fn r_squared(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (dx, dy) = (x - ma, y - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab * sab / (saa * sbb)
    }
}

/// Recognises the element of `class` that the instances in `rects` (photo pixels of `img`)
/// show. `None` when the library has no element of that class or no instance can be sampled.
pub fn recognise(
    img: &Gray,
    rects: &[Rect],
    library: &Library,
    class: Class,
) -> Option<ElementMatch> {
    let candidates: Vec<_> = library.of_class(class).collect();
    let first = candidates.first()?;
    let mut mean = vec![0.0; GRID * GRID];
    let mut instances = 0;
    for r in rects {
        if let Some(v) = normalised_instance(img, r) {
            mean.iter_mut().zip(&v).for_each(|(m, x)| *m += x);
            instances += 1;
        }
    }
    if instances == 0 {
        return None;
    }
    let inner: Vec<usize> = (0..GRID * GRID)
        .filter(|&k| {
            let inside = |i: usize| {
                let c = (i as f64 + 0.5) / GRID as f64;
                (INNER..=1.0 - INNER).contains(&c)
            };
            inside(k % GRID) && inside(k / GRID)
        })
        .collect();
    // the inner cells of a grid, less their best plane in x and y (lighting: sky reflected
    // in upper panes, shade at the bottom); the inner cells are a centred square, so the
    // constant, x and y are orthogonal there
    let centre = (GRID - 1) as f64 / 2.0;
    let coord = |k: usize| ((k % GRID) as f64 - centre, (k / GRID) as f64 - centre);
    let (sxx, syy) = inner.iter().fold((0.0, 0.0), |(a, b), &k| {
        let (x, y) = coord(k);
        (a + x * x, b + y * y)
    });
    let pick = |v: &[f64]| {
        let n = inner.len() as f64;
        let (mut m, mut vx, mut vy) = (0.0, 0.0, 0.0);
        for &k in &inner {
            let (x, y) = coord(k);
            m += v[k] / n;
            vx += v[k] * x / sxx;
            vy += v[k] * y / syy;
        }
        inner
            .iter()
            .map(|&k| {
                let (x, y) = coord(k);
                v[k] - m - vx * x - vy * y
            })
            .collect::<Vec<f64>>()
    };
    let seen = pick(&mean);
    let scores: Vec<(String, f64)> = candidates
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let mask = e.front_mask(GRID, GRID);
            // the plainest element is the null model: clear inside, it is not moved
            let shifts: &[(isize, isize)] = if k == 0 { &[(0, 0)] } else { &SHIFTS };
            let best = shifts
                .iter()
                .map(|&shift| {
                    let view = blurred(blurred(shifted(&mask, shift)));
                    r_squared(&seen, &pick(&view))
                })
                .fold(0.0, f64::max);
            (e.name.clone(), best)
        })
        .collect();
    let best = scores
        .iter()
        .skip(1)
        .filter(|s| s.1 >= MIN_EXPLAINED)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(first.name.clone(), |s| s.0.clone());
    Some(ElementMatch {
        class,
        element: best,
        scores,
        instances,
        rule: None,
    })
}

/// Recognises the element of the windows and of the doors of `grammar` (derived at the size
/// of `img`, the rectified photo it was parsed from) and makes their rules insert it. All the
/// instances of a class are recognised together first; then, where the class has several
/// rules (windows of several sizes, [`super::window_grammar`]), the instances of each rule
/// with at least [`MIN_GROUP`] of them on their own: a rule whose instances show another
/// element than the whole (explaining at least [`MIN_EXPLAINED`]) gets that element, the
/// others the whole's (a few windows averaged are noisier than all). Returns the match of
/// all the instances of each class that has any, then the matches that gave a rule its own
/// element (with [`ElementMatch::rule`] set).
pub fn recognise_elements(
    grammar: &mut Grammar,
    img: &Gray,
    library: &Library,
) -> Vec<ElementMatch> {
    let (w, h) = (img.width as f64, img.height as f64);
    let rect = |l: &super::grammar::Leaf| {
        let r = |v: f64| v.round().max(0.0) as u32;
        Rect::new(r(l.scope.x0), r(l.scope.y0), r(l.scope.x1), r(l.scope.y1))
    };
    let Ok(leaves) = grammar.derive(w, h) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    let mut own = Vec::new();
    for class in [Class::Window, Class::Door] {
        let rects: Vec<Rect> = leaves
            .iter()
            .filter(|l| l.class == class && l.element.is_none())
            .map(rect)
            .collect();
        let Some(whole) = recognise(img, &rects, library, class) else {
            continue;
        };
        let rules: Vec<String> = grammar
            .rules
            .iter()
            .filter(|(_, b)| **b == Body::Leaf(class))
            .map(|(n, _)| n.clone())
            .collect();
        // every rule inserts the element of all the instances, but for the sizes whose own
        // instances show another one
        grammar.insert_element(class, &whole.element);
        for rule in rules.iter().filter(|_| rules.len() > 1) {
            let mine: Vec<Rect> = grammar
                .leaves_of(rule, w, h)
                .unwrap_or_default()
                .iter()
                .map(rect)
                .collect();
            let m = (mine.len() >= MIN_GROUP)
                .then(|| recognise(img, &mine, library, class))
                .flatten()
                .filter(|m| m.element != whole.element && m.explained() >= MIN_EXPLAINED);
            if let Some(m) = m {
                let element = m.element.clone();
                grammar
                    .rules
                    .insert(rule.clone(), Body::Insert { class, element });
                own.push(ElementMatch {
                    rule: Some(rule.clone()),
                    ..m
                });
            }
        }
        // rules left inserting the same element are one rule again (the first of them)
        for (k, rule) in rules.iter().enumerate().skip(1) {
            let body = grammar.rules.get(rule).cloned();
            if let Some(first) = rules[..k]
                .iter()
                .find(|r| grammar.rules.get(*r) == body.as_ref())
            {
                grammar.merge_rule(rule, first);
            }
        }
        found.push(whole);
    }
    found.extend(own);
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall with `n` windows of `name`'s front view: bars light, glass dark, with noise.
    fn windows_of(lib: &Library, name: &str, n: u32) -> (Gray, Vec<Rect>) {
        let (ww, wh) = (30u32, 44u32);
        let mask = lib
            .get(name)
            .expect("element")
            .front_mask(ww as usize, wh as usize);
        let rects: Vec<Rect> = (0..n)
            .map(|k| Rect::new(10 + 50 * k, 10, 10 + 50 * k + ww, 10 + wh))
            .collect();
        let img = Gray::painted(n * 50 + 10, 64, 7, 60.0, |x, y| {
            let inside = rects
                .iter()
                .find(|r| (r.x0..r.x1).contains(&x) && (r.y0..r.y1).contains(&y));
            match inside {
                Some(r) if mask[((y - r.y0) * ww + x - r.x0) as usize] > 0.5 => 220.0,
                Some(_) => 60.0,
                None => 160.0,
            }
        });
        (img, rects)
    }

    #[test]
    fn each_window_type_is_recognised_among_the_others() {
        let lib = Library::builtin().expect("library");
        for name in [
            "window_plain",
            "window_mullion",
            "window_cross",
            "window_sash",
        ] {
            let (img, rects) = windows_of(&lib, name, 4);
            let m = recognise(&img, &rects, &lib, Class::Window).expect("recognised");
            eprintln!("{name}: {:?}", m.scores);
            assert_eq!(m.element, name, "{:?}", m.scores);
            assert_eq!(m.instances, 4);
        }
        // no door in a window's place: doors are matched among doors only
        let (img, rects) = windows_of(&lib, "window_cross", 2);
        let m = recognise(&img, &rects, &lib, Class::Door).expect("a door element");
        assert_eq!(m.element, "door_panel");
        assert!(recognise(&img, &[], &lib, Class::Window).is_none());
    }
}
