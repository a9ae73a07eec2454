//! The facade element library (Müller et al. 2007 §4 "element recognition"): 3D windows and
//! doors — frames, mullions, transoms, panels — as closed meshes in the unit square of their
//! opening. This module owns the elements, their front views (what recognition in
//! [`super::element_match`] compares with the photo) and their insertion into a generated
//! facade mesh ([`insert_elements`]). The built-in elements are the OBJ files of
//! `assets/facade_elements/` (their README gives the conventions), compiled in.

use std::path::Path;

use super::facade_mesh::{FacadeMesh, Group, MeshParams, Surface};
use super::grammar::Leaf;
use super::labels::Class;
use crate::geometry::obj::obj_surface_from_text;
use crate::geometry::Vec3;

/// The built-in elements: (name, OBJ text).
const BUILTIN: [(&str, &str); 7] = [
    (
        "window_plain",
        include_str!("../../assets/facade_elements/window_plain.obj"),
    ),
    (
        "window_mullion",
        include_str!("../../assets/facade_elements/window_mullion.obj"),
    ),
    (
        "window_cross",
        include_str!("../../assets/facade_elements/window_cross.obj"),
    ),
    (
        "window_sash",
        include_str!("../../assets/facade_elements/window_sash.obj"),
    ),
    (
        "door_panel",
        include_str!("../../assets/facade_elements/door_panel.obj"),
    ),
    (
        "wall_frame",
        include_str!("../../assets/facade_elements/wall_frame.obj"),
    ),
    (
        "wall_sill",
        include_str!("../../assets/facade_elements/wall_sill.obj"),
    ),
];

/// How far (in units of the opening) an element may reach outside its unit square.
const SLACK: f64 = 1e-9;

/// One element: a closed mesh whose x and y span its opening (0..1, y up) and whose z is in
/// metres from the back of the opening, towards the street.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Name (`window_cross`); its prefix before `_` is the class it is for (`wall_` for the
    /// mouldings tile refinement puts round and below windows).
    pub name: String,
    /// The class it is inserted in.
    pub class: Class,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
}

impl Element {
    /// Reads an element from OBJ text; `name` gives its class (`window_…`, `door_…`). Errors
    /// name the element: a malformed file, an unknown class prefix, or a vertex outside the
    /// opening's unit square.
    pub fn from_obj(name: &str, text: &str) -> Result<Element, String> {
        let file = format!("{name}.obj");
        let (positions, triangles) =
            obj_surface_from_text(text, Path::new(&file)).map_err(|e| e.to_string())?;
        let prefix = name.split('_').next().unwrap_or("");
        let class = Class::from_name(prefix)
            .filter(|c| {
                matches!(
                    c,
                    Class::Window | Class::Door | Class::Balcony | Class::Wall
                )
            })
            .ok_or_else(|| {
                format!(
                    "element {file}: the name must start with window_, door_, balcony_ or wall_"
                )
            })?;
        let inside = |v: f64| (-SLACK..=1.0 + SLACK).contains(&v);
        if let Some(i) = positions
            .iter()
            .position(|p| !(inside(p.x) && inside(p.y) && p.z.is_finite()))
        {
            return Err(format!(
                "element {file}: vertex {} at {:?} lies outside the opening (x and y in 0..1)",
                i + 1,
                positions[i].as_slice()
            ));
        }
        Ok(Element {
            name: name.to_string(),
            class,
            positions,
            triangles,
        })
    }

    /// The element seen from the front on a `w` × `h` grid of the opening (row 0 at the top):
    /// 1 where it covers the centre of a cell, 0 where the opening is clear (the glass).
    pub fn front_mask(&self, w: usize, h: usize) -> Vec<f64> {
        let mut mask = vec![0.0; w * h];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i]);
            let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if area.abs() < 1e-12 {
                continue; // seen edge-on
            }
            let edge = |p: Vec3, q: Vec3, x: f64, y: f64| {
                ((q.x - p.x) * (y - p.y) - (x - p.x) * (q.y - p.y)) * area.signum()
            };
            let (xmin, xmax) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
            let (ymin, ymax) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
            let cols = cells(xmin, xmax, w);
            let rows = cells(1.0 - ymax, 1.0 - ymin, h);
            for r in rows {
                let y = 1.0 - (r as f64 + 0.5) / h as f64;
                for k in cols.clone() {
                    let x = (k as f64 + 0.5) / w as f64;
                    if edge(a, b, x, y) >= 0.0 && edge(b, c, x, y) >= 0.0 && edge(c, a, x, y) >= 0.0
                    {
                        mask[r * w + k] = 1.0;
                    }
                }
            }
        }
        mask
    }
}

/// Cells of a grid of `n` over 0..1 whose centres may lie in `[lo, hi]`.
fn cells(lo: f64, hi: f64, n: usize) -> std::ops::Range<usize> {
    let first = ((lo * n as f64 - 0.5).ceil().max(0.0)) as usize;
    let end = ((hi * n as f64 - 0.5).floor() + 1.0).clamp(0.0, n as f64) as usize;
    first.min(end)..end
}

/// A set of elements.
#[derive(Debug, Clone, PartialEq)]
pub struct Library {
    /// The elements, the plainest of each class first.
    pub elements: Vec<Element>,
}

impl Library {
    /// The built-in elements (`assets/facade_elements/`).
    pub fn builtin() -> Result<Library, String> {
        let elements = BUILTIN
            .iter()
            .map(|(name, text)| Element::from_obj(name, text))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Library { elements })
    }

    /// The element called `name`.
    pub fn get(&self, name: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.name == name)
    }

    /// The elements for `class`, in library order.
    pub fn of_class(&self, class: Class) -> impl Iterator<Item = &Element> {
        self.elements.iter().filter(move |e| e.class == class)
    }
}

/// Adds the elements that `leaves` insert to `mesh` (built from the same leaves by
/// [`super::facade_mesh::build`]) as closed solids of their own, in one last group
/// ([`Surface::Element`]): each scaled to its leaf's opening and set against the back of its
/// recess. `names` is [`super::grammar::Grammar::elements`]. Errors name an element missing
/// from the library; returns how many were inserted.
pub fn insert_elements(
    mesh: &mut FacadeMesh,
    leaves: &[Leaf],
    names: &[String],
    library: &Library,
    params: &MeshParams,
) -> Result<usize, String> {
    let (mut xmin, mut ymax) = (f64::INFINITY, f64::NEG_INFINITY);
    for l in leaves {
        xmin = xmin.min(l.scope.x0);
        ymax = ymax.max(l.scope.y1);
    }
    let start = mesh.triangles.len();
    let uv = mesh.uvs.len();
    let mut count = 0;
    for l in leaves {
        let Some(k) = l.element else { continue };
        let name = names
            .get(k)
            .ok_or_else(|| format!("leaf element {k} has no name ({} known)", names.len()))?;
        let e = library
            .get(name)
            .ok_or_else(|| format!("element {name} is not in the library"))?;
        let s = params.scale;
        let (x0, x1) = ((l.scope.x0 - xmin) * s, (l.scope.x1 - xmin) * s);
        let (y0, y1) = ((ymax - l.scope.y1) * s, (ymax - l.scope.y0) * s);
        let back = -params.depth(l.class);
        let base = mesh.positions.len();
        mesh.positions.extend(
            e.positions
                .iter()
                .map(|p| Vec3::new(x0 + p.x * (x1 - x0), y0 + p.y * (y1 - y0), back + p.z)),
        );
        mesh.triangles
            .extend(e.triangles.iter().map(|t| t.map(|i| base + i)));
        count += 1;
    }
    if mesh.triangles.len() > start {
        mesh.uvs.push([0.0, 0.0]);
        mesh.uv_triangles.resize(mesh.triangles.len(), [uv, uv, uv]);
        mesh.groups.push(Group {
            surface: Surface::Element,
            triangles: start..mesh.triangles.len(),
        });
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtin_elements_load_and_show_their_bars_from_the_front() {
        let lib = Library::builtin().expect("built-in elements");
        assert_eq!(lib.of_class(Class::Window).count(), 4);
        assert_eq!(lib.of_class(Class::Door).count(), 1);
        assert_eq!(lib.of_class(Class::Wall).count(), 2);
        let (w, h) = (20, 20);
        let at = |m: &[f64], x: usize, y: usize| m[y * w + x];
        let plain = lib.get("window_plain").expect("plain").front_mask(w, h);
        let cross = lib.get("window_cross").expect("cross").front_mask(w, h);
        let sash = lib.get("window_sash").expect("sash").front_mask(w, h);
        // the frame round the border, clear inside
        assert_eq!((at(&plain, 0, 10), at(&plain, 10, 0)), (1.0, 1.0));
        assert_eq!(at(&plain, 10, 10), 0.0);
        // the cross's mullion in the middle column, its transom at 0.65 of the height
        // (row 7 from the top: y = 1 − 7.5/20 = 0.625 ∈ [0.615, 0.685])
        assert_eq!((at(&cross, 10, 15), at(&cross, 5, 7)), (1.0, 1.0));
        assert_eq!((at(&cross, 5, 12), at(&cross, 5, 5)), (0.0, 0.0));
        // the sash's rail at half height, no mullion
        assert_eq!((at(&sash, 5, 10), at(&sash, 10, 5)), (1.0, 0.0));
    }

    #[test]
    fn an_element_outside_its_opening_or_of_no_class_is_refused() {
        let box_at = |x: f64| format!("v {x} 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
        let e = Element::from_obj("window_big", &box_at(-0.5)).unwrap_err();
        assert!(e.contains("window_big.obj") && e.contains("outside"), "{e}");
        let e = Element::from_obj("chimney_pot", &box_at(0.0)).unwrap_err();
        assert!(e.contains("must start with"), "{e}");
        let e = Element::from_obj("window_x", "v 0 0\n").unwrap_err();
        assert!(e.contains("window_x.obj"), "{e}");
    }
}
