//! Broad phase for cloth–cloth contact: a loose uniform grid hashed into a fixed table (Teschner et
//! al. 2003), rebuilt from the primitives' boxes each time it is used. Boxes are binned by a
//! counting sort (no per-entry allocation once warm); queries return the ids of boxes that
//! really overlap (hash collisions filtered), each once, in an order fixed by the boxes alone,
//! so results do not depend on thread timing.

use crate::geometry::Vec3;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (grows from anything).
    pub fn empty() -> Aabb {
        Aabb {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        }
    }

    /// Grows the box to hold `p`.
    #[inline]
    pub fn grow(&mut self, p: &Vec3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }

    /// The box enlarged by `r` on every side.
    #[inline]
    pub fn inflated(&self, r: f64) -> Aabb {
        Aabb {
            min: self.min - Vec3::repeat(r),
            max: self.max + Vec3::repeat(r),
        }
    }

    /// Whether the boxes overlap (touching counts).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.x <= o.max.x
            && o.min.x <= self.max.x
            && self.min.y <= o.max.y
            && o.min.y <= self.max.y
            && self.min.z <= o.max.z
            && o.min.z <= self.max.z
    }
}

/// The hashed grid over a set of boxes: a loose grid, each box stored once in the cell of its
/// centre; queries widen their box by the largest stored half-extent. Boxes much larger than a
/// cell go to a list every query scans.
#[derive(Debug, Clone, Default)]
pub struct SpatialHash {
    cell: f64,
    mask: usize,
    starts: Vec<u32>,
    entries: Vec<u32>,
    boxes: Vec<Aabb>,
    home: Vec<(i64, i64, i64)>,
    margin: Vec3,
    large: Vec<u32>,
}

/// Boxes with a half-extent above this many cells are scanned by every query instead.
const LARGE: f64 = 1.0;

/// A query box covering more than this many cells along an axis scans every box.
const MAX_SPAN: i64 = 32;

/// ⌊v / cell⌋ without a libm call (saturating for huge or non-finite values).
#[inline]
fn cell_of(v: f64, cell: f64) -> i64 {
    let t = v / cell;
    let i = t as i64;
    if (i as f64) > t {
        i - 1
    } else {
        i
    }
}

#[inline]
fn cell_hash(i: i64, j: i64, k: i64) -> usize {
    ((i.wrapping_mul(73_856_093)) ^ (j.wrapping_mul(19_349_663)) ^ (k.wrapping_mul(83_492_791)))
        as usize
}

impl SpatialHash {
    /// Rebuilds the grid over `boxes` with cells of size `cell` (m).
    pub fn build(&mut self, boxes: &[Aabb], cell: f64) {
        self.cell = cell.max(1e-9);
        let cell = self.cell;
        let want = (boxes.len() * 2).max(64).next_power_of_two();
        self.mask = want - 1;
        self.starts.clear();
        self.starts.resize(want + 1, 0);
        self.boxes.clear();
        self.boxes.extend_from_slice(boxes);
        self.home.clear();
        self.large.clear();
        self.margin = Vec3::zeros();
        for (id, b) in boxes.iter().enumerate() {
            let half = (b.max - b.min) * 0.5;
            let c = (b.max + b.min) * 0.5;
            let finite = c.iter().chain(half.iter()).all(|v| v.is_finite());
            if !finite || half.max() > LARGE * cell {
                self.large.push(id as u32);
                self.home.push((i64::MIN, i64::MIN, i64::MIN));
                continue;
            }
            self.margin = self.margin.sup(&half);
            let h = (cell_of(c.x, cell), cell_of(c.y, cell), cell_of(c.z, cell));
            self.home.push(h);
            self.starts[(cell_hash(h.0, h.1, h.2) & self.mask) + 1] += 1;
        }
        for k in 0..want {
            self.starts[k + 1] += self.starts[k];
        }
        self.entries.clear();
        self.entries.resize(self.starts[want] as usize, 0);
        let mut fill = std::mem::take(&mut self.starts);
        let starts = fill.clone();
        for (id, h) in self.home.iter().enumerate() {
            if h.0 == i64::MIN {
                continue;
            }
            let slot = &mut fill[cell_hash(h.0, h.1, h.2) & self.mask];
            self.entries[*slot as usize] = id as u32;
            *slot += 1;
        }
        self.starts = starts;
    }

    /// Ids of the stored boxes overlapping `b`, each once, into `out` (cleared first), in an
    /// order that depends only on the boxes.
    pub fn query(&self, b: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        if self.boxes.is_empty() {
            return;
        }
        let cell = self.cell;
        let wide = Aabb {
            min: b.min - self.margin,
            max: b.max + self.margin,
        };
        let (i0, j0, k0) = (
            cell_of(wide.min.x, cell),
            cell_of(wide.min.y, cell),
            cell_of(wide.min.z, cell),
        );
        let (i1, j1, k1) = (
            cell_of(wide.max.x, cell),
            cell_of(wide.max.y, cell),
            cell_of(wide.max.z, cell),
        );
        let span = |a: i64, z: i64| {
            z.checked_sub(a)
                .is_none_or(|d| !(0..=MAX_SPAN).contains(&d))
        };
        let finite = wide
            .min
            .iter()
            .chain(wide.max.iter())
            .all(|c| c.is_finite());
        if !finite || span(i0, i1) || span(j0, j1) || span(k0, k1) {
            // a huge query box: scan everything
            for (id, bx) in self.boxes.iter().enumerate() {
                if bx.overlaps(b) {
                    out.push(id as u32);
                }
            }
            return;
        }
        for i in i0..=i1 {
            for j in j0..=j1 {
                for k in k0..=k1 {
                    let h = cell_hash(i, j, k) & self.mask;
                    for &id in &self.entries[self.starts[h] as usize..self.starts[h + 1] as usize] {
                        // the home check drops other cells hashed to the same bucket
                        if self.home[id as usize] == (i, j, k)
                            && self.boxes[id as usize].overlaps(b)
                        {
                            out.push(id);
                        }
                    }
                }
            }
        }
        for &id in &self.large {
            if self.boxes[id as usize].overlaps(b) {
                out.push(id);
            }
        }
    }
}
