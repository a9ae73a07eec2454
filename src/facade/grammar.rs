//! The facade shape grammar (Müller et al. 2006–2007, CGA-like): a tree of splits and repeats
//! whose leaves are facade classes, its derivation into labelled rectangles at any size, and
//! its rule file. A [`Grammar`] (its rules) is what a parse produces; deriving it at the photo's size
//! reproduces the parse, and at other sizes generates new facades of the same style.
//!
//! Sizes follow CGA: a part is either **fixed** (`12.5`: its size in facade units whatever
//! the scope) or **floating** (`~30`: a relative weight sharing what the fixed parts leave).
//! `repeat` fills its scope with as many tiles of its nominal size as fit (at least one),
//! stretched to fill it exactly. The rule file reads back into the same rules
//! ([`Grammar::parse`]), so the file alone regenerates the facade.

use std::collections::BTreeMap;

use super::labels::Class;

/// A rectangle in facade units (pixels of the rectified photo at the parse's own size),
/// y down: `[x0, x1) × [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scope {
    /// Left.
    pub x0: f64,
    /// Top.
    pub y0: f64,
    /// Right.
    pub x1: f64,
    /// Bottom.
    pub y1: f64,
}

impl Scope {
    /// Width.
    pub fn width(&self) -> f64 {
        self.x1 - self.x0
    }
    /// Height.
    pub fn height(&self) -> f64 {
        self.y1 - self.y0
    }
    fn along(&self, axis: Dir) -> (f64, f64) {
        match axis {
            Dir::X => (self.x0, self.x1),
            Dir::Y => (self.y0, self.y1),
        }
    }
    fn with(&self, axis: Dir, a: f64, b: f64) -> Scope {
        match axis {
            Dir::X => Scope {
                x0: a,
                x1: b,
                ..*self
            },
            Dir::Y => Scope {
                y0: a,
                y1: b,
                ..*self
            },
        }
    }
}

/// Split direction: `X` cuts the scope into columns (left to right), `Y` into rows (top to
/// bottom).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Columns.
    X,
    /// Rows.
    Y,
}

impl Dir {
    pub(super) fn name(self) -> &'static str {
        match self {
            Dir::X => "x",
            Dir::Y => "y",
        }
    }
}

/// The size of a split part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Size {
    /// Fixed, in facade units.
    Fixed(f64),
    /// Floating: a relative weight of what the fixed parts leave.
    Floating(f64),
}

/// The right-hand side of a rule.
#[derive(Debug, Clone, PartialEq)]
pub enum Body {
    /// Cut the scope along a direction into parts, each given to a rule.
    Split {
        /// Direction.
        dir: Dir,
        /// (size, rule name) of each part, in order.
        parts: Vec<(Size, String)>,
    },
    /// Fill the scope along a direction with copies of one rule, each about `size` long.
    Repeat {
        /// Direction.
        dir: Dir,
        /// Nominal tile size (facade units).
        size: f64,
        /// The tile's rule.
        rule: String,
    },
    /// A terminal shape of a class.
    Leaf(Class),
    /// A terminal shape of a class with an element of the library inserted in it (CGA's `i`):
    /// a window type, a door ([`super::element_library`]).
    Insert {
        /// The class.
        class: Class,
        /// The element's name in the library.
        element: String,
    },
}

/// A derived terminal shape: where it is, what it is, and where it came from in the parsed
/// photo (the same place at the parse's own size; in a resized facade, the corresponding
/// place of the tile it repeats), so generated facades can be textured with the photo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leaf {
    /// Where it is.
    pub scope: Scope,
    /// Its class.
    pub class: Class,
    /// The corresponding rectangle of the parsed photo.
    pub source: Scope,
    /// The inserted element, as an index into [`Grammar::elements`]; `None` for a plain leaf.
    pub element: Option<usize>,
}

/// A facade grammar: named rules and the axiom's size.
#[derive(Debug, Clone, PartialEq)]
pub struct Grammar {
    /// Rules by name.
    pub rules: BTreeMap<String, Body>,
    /// The start rule.
    pub axiom: String,
    /// Width and height of the parsed facade (facade units).
    pub size: (f64, f64),
}

/// A derivation in progress: the elements leaves index, the most shapes it may make
/// (`max_elements`), and the shapes made.
struct Derivation {
    elements: Vec<String>,
    max: u64,
    out: Vec<Leaf>,
}

/// Deepest derivation: a rule that reaches itself is an error, not a stack overflow.
const MAX_DEPTH: usize = 64;

impl Grammar {
    /// Derives the facade at `width` × `height`: the terminal shapes, in derivation order.
    /// Errors name the rule: an unknown rule, a cycle, a non-positive size, fixed parts
    /// that do not fit their scope, or more shapes than the `max_elements` limit (counted
    /// before a repeat makes its tiles).
    pub fn derive(&self, width: f64, height: f64) -> Result<Vec<Leaf>, String> {
        if !(width > 0.0 && height > 0.0 && width.is_finite() && height.is_finite()) {
            return Err(format!("facade size {width} × {height} must be positive"));
        }
        let scope = Scope {
            x0: 0.0,
            y0: 0.0,
            x1: width,
            y1: height,
        };
        let source = Scope {
            x0: 0.0,
            y0: 0.0,
            x1: self.size.0,
            y1: self.size.1,
        };
        let mut d = Derivation {
            elements: self.elements(),
            max: crate::limits::get().max_elements,
            out: Vec::new(),
        };
        self.expand(&self.axiom, scope, source, 0, &mut d)?;
        Ok(d.out)
    }

    /// The distinct elements the rules insert, sorted by name: what [`Leaf::element`] indexes.
    pub fn elements(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .rules
            .values()
            .filter_map(|b| match b {
                Body::Insert { element, .. } => Some(element.clone()),
                _ => None,
            })
            .collect();
        v.sort();
        v.dedup();
        v
    }

    /// Makes every plain leaf of `class` insert `element` (the rule file then says
    /// `insert(class, element)`); returns how many rules changed.
    pub fn insert_element(&mut self, class: Class, element: &str) -> usize {
        let mut n = 0;
        for body in self.rules.values_mut() {
            if *body == Body::Leaf(class) {
                *body = Body::Insert {
                    class,
                    element: element.to_string(),
                };
                n += 1;
            }
        }
        n
    }

    /// Makes every reference to rule `from` one to `into` and removes `from` (rules with the
    /// same body merged: the rule file says it once).
    pub fn merge_rule(&mut self, from: &str, into: &str) {
        if from == into || !self.rules.contains_key(into) {
            return;
        }
        self.rules.remove(from);
        for body in self.rules.values_mut() {
            match body {
                Body::Split { parts, .. } => parts
                    .iter_mut()
                    .filter(|(_, r)| r == from)
                    .for_each(|(_, r)| *r = into.to_string()),
                Body::Repeat { rule, .. } if rule == from => *rule = into.to_string(),
                _ => {}
            }
        }
        if self.axiom == from {
            self.axiom = into.to_string();
        }
    }

    /// The leaves that rule `name` (a terminal rule: a leaf or an insert) makes when the
    /// facade is derived at `width` × `height`, without their elements; empty for a rule that
    /// is not terminal.
    pub fn leaves_of(&self, name: &str, width: f64, height: f64) -> Result<Vec<Leaf>, String> {
        let class = match self.rules.get(name) {
            Some(Body::Leaf(class) | Body::Insert { class, .. }) => class,
            _ => return Ok(Vec::new()),
        };
        // the rule marked with an element no rule file can name
        const MARK: &str = "\u{0}mark";
        let mut marked = self.clone();
        marked.rules.insert(
            name.to_string(),
            Body::Insert {
                class: *class,
                element: MARK.into(),
            },
        );
        let k = marked.elements().iter().position(|e| e == MARK);
        Ok(marked
            .derive(width, height)?
            .into_iter()
            .filter(|l| l.element == k)
            .map(|l| Leaf { element: None, ..l })
            .collect())
    }

    fn expand(
        &self,
        name: &str,
        scope: Scope,
        source: Scope,
        depth: usize,
        d: &mut Derivation,
    ) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!(
                "rule {name}: derivation deeper than {MAX_DEPTH} (a cycle?)"
            ));
        }
        let body = self
            .rules
            .get(name)
            .ok_or_else(|| format!("unknown rule {name}"))?;
        if matches!(body, Body::Leaf(_) | Body::Insert { .. }) {
            check_shapes(name, d.out.len(), 1.0, d.max)?;
        }
        match body {
            Body::Leaf(class) => d.out.push(Leaf {
                scope,
                class: *class,
                source,
                element: None,
            }),
            Body::Insert { class, element } => d.out.push(Leaf {
                scope,
                class: *class,
                source,
                element: d.elements.binary_search(element).ok(),
            }),
            Body::Split { dir, parts } => {
                let sizes: Vec<Size> = parts.iter().map(|p| p.0).collect();
                let (a, b) = scope.along(*dir);
                let (sa, sb) = source.along(*dir);
                let cuts =
                    split_positions(&sizes, a, b).map_err(|e| format!("rule {name}: {e}"))?;
                let scuts =
                    split_positions(&sizes, sa, sb).map_err(|e| format!("rule {name}: {e}"))?;
                for (k, (_, rule)) in parts.iter().enumerate() {
                    self.expand(
                        rule,
                        scope.with(*dir, cuts[k], cuts[k + 1]),
                        source.with(*dir, scuts[k], scuts[k + 1]),
                        depth + 1,
                        d,
                    )?;
                }
            }
            Body::Repeat { dir, size, rule } => {
                if !(*size > 0.0 && size.is_finite()) {
                    return Err(format!("rule {name}: repeat size {size} must be positive"));
                }
                let (a, b) = scope.along(*dir);
                let (sa, sb) = source.along(*dir);
                // each tile makes one shape at least: count them before making any
                check_shapes(name, d.out.len(), ((b - a) / size).round(), d.max)?;
                let n = repeat_count(b - a, *size);
                let ns = repeat_count(sb - sa, *size);
                for k in 0..n {
                    // the k-th tile shows the photo's tile at the same place from the start,
                    // wrapping round the photo's tiles
                    let ks = k % ns;
                    let step = (b - a) / n as f64;
                    let sstep = (sb - sa) / ns as f64;
                    self.expand(
                        rule,
                        scope.with(*dir, a + k as f64 * step, a + (k + 1) as f64 * step),
                        source.with(*dir, sa + ks as f64 * sstep, sa + (ks + 1) as f64 * sstep),
                        depth + 1,
                        d,
                    )?;
                }
            }
        }
        Ok(())
    }
}

/// Checks that a derivation that has made `made` shapes may make `more` (a float: a repeat's
/// tile count before it is rounded to an integer) without passing the `max_elements` limit;
/// `rule` names the rule in the error.
pub fn check_shapes(rule: &str, made: usize, more: f64, max: u64) -> Result<(), String> {
    let total = made as f64 + more;
    if total.is_finite() && total <= max as f64 {
        Ok(())
    } else {
        Err(format!(
            "rule {rule}: the derivation makes {total:.0} shapes or more, over the limit max_elements = {max} (raise it with `emilion run --limit max_elements=N`)"
        ))
    }
}

/// Tiles of nominal `size` that fill `extent`: the nearest whole number, at least one.
pub fn repeat_count(extent: f64, size: f64) -> usize {
    ((extent / size).round() as usize).max(1)
}

/// Cut positions of a split of `[a, b]` into parts of `sizes`: fixed parts keep their size,
/// floating ones share the rest by weight. When the fixed parts alone overflow the scope (a
/// facade derived smaller than its parse), they shrink in proportion and floating parts get
/// nothing: a derivation never makes negative or overlapping shapes.
pub fn split_positions(sizes: &[Size], a: f64, b: f64) -> Result<Vec<f64>, String> {
    if sizes.is_empty() {
        return Err("a split needs at least one part".into());
    }
    let extent = b - a;
    let fixed: f64 = sizes
        .iter()
        .map(|s| if let Size::Fixed(v) = s { *v } else { 0.0 })
        .sum();
    let weights: f64 = sizes
        .iter()
        .map(|s| if let Size::Floating(v) = s { *v } else { 0.0 })
        .sum();
    let (fixed_scale, float_unit) = if fixed > extent || weights <= 0.0 {
        // shrink (or stretch, with nothing floating) the fixed parts to fit exactly
        (if fixed > 0.0 { extent / fixed } else { 0.0 }, 0.0)
    } else {
        (1.0, (extent - fixed) / weights)
    };
    if fixed <= 0.0 && weights <= 0.0 {
        return Err("every part has size 0".into());
    }
    let mut cuts = Vec::with_capacity(sizes.len() + 1);
    let mut at = a;
    cuts.push(at);
    for s in sizes {
        at += match s {
            Size::Fixed(v) => v * fixed_scale,
            Size::Floating(w) => w * float_unit,
        };
        cuts.push(at);
    }
    // the last cut is exactly the scope's end, whatever the rounding
    *cuts.last_mut().expect("cuts") = b;
    Ok(cuts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Grammar {
        Grammar::parse(
            "// axiom Facade size 430 300\n\
             Facade --> split(y) { 30: Top | ~1: Floors | 42.5: Ground }\n\
             Floors --> repeat(y, 57) { Floor }\n\
             Floor --> split(x) { 43: Wall | ~344: Tiles | 43: Wall }\n\
             Tiles --> repeat(x, 43) { Tile }\n\
             Tile --> split(x) { ~10: Wall | 24: Col | ~9: Wall }\n\
             Col --> split(y) { ~12: Wall | 33: Window | ~12: Wall }\n\
             Top --> background\nGround --> door\nWall --> wall\nWindow --> window\n",
        )
        .expect("parses")
    }

    #[test]
    fn text_round_trips_and_derivation_fills_the_scope() {
        let g = sample();
        let back = Grammar::parse(&g.to_text()).expect("reads its own text");
        assert_eq!(back, g);
        let leaves = g.derive(430.0, 300.0).expect("derives");
        let area: f64 = leaves
            .iter()
            .map(|l| l.scope.width() * l.scope.height())
            .sum();
        assert!(
            (area - 430.0 * 300.0).abs() < 1e-6,
            "leaves tile the facade: {area}"
        );
        // 300 − 72.5 = 227.5 → 4 floors; 8 tiles; one window each
        let windows = leaves.iter().filter(|l| l.class == Class::Window).count();
        assert_eq!(windows, 4 * 8);
        for l in &leaves {
            assert_eq!(
                l.scope, l.source,
                "at its own size the source is the place itself"
            );
        }
        // at 1.5×: floors follow round((450 − 72.5)/57) = 7, tiles round((645 − 86)/43) = 13
        let wide = g.derive(645.0, 450.0).expect("derives");
        let w2 = wide.iter().filter(|l| l.class == Class::Window).count();
        assert_eq!(w2, 7 * 13);
        // window sizes stay absolute
        for l in wide.iter().filter(|l| l.class == Class::Window) {
            assert!(
                (l.scope.width() - 24.0).abs() < 1e-9 && (l.scope.height() - 33.0).abs() < 1e-9
            );
        }
    }

    #[test]
    fn inserted_elements_read_back_and_reach_the_leaves() {
        let mut g = sample();
        assert_eq!(g.insert_element(Class::Window, "window_cross"), 1);
        assert_eq!(g.insert_element(Class::Door, "door_panel"), 1);
        let text = g.to_text();
        assert!(
            text.contains("Window --> insert(window, window_cross)"),
            "{text}"
        );
        let back = Grammar::parse(&text).expect("reads inserts");
        assert_eq!(back, g);
        let names = back.elements();
        assert_eq!(names, vec!["door_panel", "window_cross"]);
        for l in back.derive(430.0, 300.0).expect("derives") {
            let want = match l.class {
                Class::Window => Some(1),
                Class::Door => Some(0),
                _ => None,
            };
            assert_eq!(l.element, want, "{l:?}");
        }
        let e = Grammar::parse("// axiom F size 1 1\nF --> insert(window, a-b)\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("element name"), "{e}");
        let e = Grammar::parse("// axiom F size 1 1\nF --> insert(chimney, pot)\n").unwrap_err();
        assert!(e.contains("class"), "{e}");
    }

    #[test]
    fn bad_rules_are_rejected_with_the_line() {
        let e = Grammar::parse("// axiom F size 10 10\nF --> split(z) { 1: A }\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("direction"), "{e}");
        let e = Grammar::parse("// axiom F size 10 10\nF --> split(x) { 1: A }\n").unwrap_err();
        assert!(e.contains("unknown rule A"), "{e}");
        let e = Grammar::parse("// axiom F size 10 10\nF --> repeat(x, 5) { F }\n")
            .expect("parses")
            .derive(10.0, 10.0)
            .unwrap_err();
        assert!(e.contains("cycle"), "{e}");
    }

    #[test]
    fn fixed_parts_shrink_instead_of_overflowing() {
        let c = split_positions(
            &[Size::Fixed(6.0), Size::Floating(1.0), Size::Fixed(6.0)],
            0.0,
            10.0,
        )
        .expect("fits");
        assert_eq!(c, vec![0.0, 5.0, 5.0, 10.0]);
    }
}
