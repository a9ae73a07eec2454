//! `Bcsr3`: a square block-sparse matrix of 3×3 blocks in compressed-row form. The pattern is
//! built once per topology; values are refilled in place each step; the product is row-parallel
//! and deterministic (each output row is computed by one thread in a fixed order).

use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
use super::simd::Level;
use crate::geometry::{Mat3, Vec3};

/// Rows per parallel task.
pub const ROW_CHUNK: usize = 256;

/// Most blocks in one row of a matrix stored without general blocks (its rows are summed in a
/// fixed-size local buffer): a grid cloth's rows have 13, or 21 with interlaced connections.
pub const SYM_ROW_MAX: usize = 32;

/// Block compressed-row matrix with 3×3 blocks.
#[derive(Debug, Clone, Default)]
pub struct Bcsr3 {
    /// Start of each row's blocks in `cols`/`values` (length rows + 1).
    pub row_ptr: Vec<usize>,
    /// Block column of each stored block.
    pub cols: Vec<u32>,
    /// Block values (empty when the blocks are stored symmetric, in `sym`, or not at all in
    /// double precision: see [`Bcsr3::store_symmetric`] and [`Bcsr3::store_single_only`]).
    pub values: Vec<Mat3>,
    /// Block values as symmetric blocks, when every block is symmetric (grid cloths: springs
    /// only) and [`Bcsr3::store_symmetric`] chose this storage: two thirds of the bytes of
    /// `values`, which the conjugate gradient's products stream once per iteration.
    pub sym: Vec<Sym3>,
    /// Index of the diagonal block of each row.
    pub diag: Vec<usize>,
    /// Optional single-precision mirror of `values` (empty unless enabled), read by the
    /// multigrid smoother where memory traffic, not precision, is the cost.
    pub values32: Vec<Sym3f>,
    /// Column offsets of the mirror's full rows (see [`grid_stencil`]).
    pub stencil32: Vec<i32>,
    /// Optional second copy of the mirror with the rows stored in another order (see
    /// [`PermutedMirror`]); filled by whoever fills `values32`.
    pub permuted: Option<PermutedMirror>,
}

/// The single-precision mirror's blocks again, renumbered: stored row `p` is original row
/// `order[p]`, and columns carry the new numbers too, so the copy is the matrix `Qᵀ A Q` of
/// the permutation `Q`. A smoother that walks lines across the row order (a grid's weft lines)
/// then works on vectors permuted the same way and streams through memory: reading the
/// original rows and vectors along a weft line touched every row of the matrix for each of its
/// colours, and a new cache line and page of each vector at every particle (at 256², a stride
/// of 6 KB).
#[derive(Debug, Clone, Default)]
pub struct PermutedMirror {
    /// Original row of each stored row.
    pub order: Vec<u32>,
    /// Start of each stored row in `cols`/`values` (length rows + 1).
    pub start: Vec<usize>,
    /// Where each original row starts in `values`.
    pub row_start: Vec<usize>,
    /// Block column (new numbering) of each stored block, in the original row's order (not
    /// sorted).
    pub cols: Vec<u32>,
    /// Index of the diagonal block of each stored row.
    pub diag: Vec<usize>,
    /// Block values, in the stored order.
    pub values: Vec<Sym3f>,
    /// Column offsets of the full rows (see [`grid_stencil`]).
    pub stencil: Vec<i32>,
}

impl PermutedMirror {
    /// The stored rows.
    pub fn rows(&self) -> Rows32<'_> {
        Rows32 {
            start: &self.start,
            cols: &self.cols,
            diag: &self.diag,
            values: &self.values,
            stencil: &self.stencil,
        }
    }
}

/// Single-precision rows as a smoother reads them: the mirror in row order, or a permuted copy.
#[derive(Debug, Clone, Copy)]
pub struct Rows32<'a> {
    /// Start of each stored row in `cols`/`values`.
    pub start: &'a [usize],
    /// Block column of each block (in the stored rows' numbering).
    pub cols: &'a [u32],
    /// Index of the diagonal block of each stored row.
    pub diag: &'a [usize],
    /// Block values.
    pub values: &'a [Sym3f],
    /// Column offsets shared by every row with as many blocks as it has entries (empty: none):
    /// such a row's columns are not read from `cols`.
    pub stencil: &'a [i32],
}

/// The body of [`Rows32::row_times_ptr`] with the row product `$kernel` (an unsafe function
/// like [`sym_row_product`]), so that each form inlines its own.
macro_rules! row_product {
    ($rows:expr, $p:expr, $x:expr, $kernel:ident) => {{
        let (rows, p, x) = ($rows, $p, $x);
        let (s, e) = (rows.start[p], rows.start[p + 1]);
        let values = &rows.values[s..e];
        if e - s == rows.stencil.len() {
            // the columns of a full row are p + the stencil's offsets (checked when the
            // stencil was found): 13 fewer words per row to stream at every product
            let cols = rows
                .stencil
                .iter()
                .map(|&o| (p as isize + o as isize) as usize);
            $kernel(values, cols, x)
        } else {
            let cols = rows.cols[s..e].iter().map(|&c| c as usize);
            $kernel(values, cols, x)
        }
    }};
}

impl Rows32<'_> {
    /// Index of block (stored row `p`, column `j`), if it is in the pattern (a linear search:
    /// the permuted copy's columns are not sorted).
    pub fn slot(&self, p: usize, j: usize) -> Option<usize> {
        let (s, e) = (self.start[p], self.start[p + 1]);
        self.cols[s..e]
            .iter()
            .position(|&c| c == j as u32)
            .map(|k| s + k)
    }

    /// Stored row `p` times `x`, accumulated in double precision, reading `x` through a raw
    /// pointer.
    ///
    /// # Safety
    /// `x` must point to as many vectors as the matrix has rows; no other thread may write the
    /// entries this row reads.
    #[inline]
    pub unsafe fn row_times_ptr(&self, p: usize, x: *const Vec3) -> Vec3 {
        #[cfg(target_arch = "x86_64")]
        match super::simd::level() {
            // SAFETY: forwarded from the caller; the CPU has the features (checked at run time).
            Level::Avx512 => return unsafe { self.row_times_ptr_avx512(p, x) },
            // SAFETY: as above.
            Level::Avx2 => return unsafe { self.row_times_ptr_avx2(p, x) },
            Level::Generic => {}
        }
        // SAFETY: forwarded from the caller.
        unsafe { row_product!(self, p, x, sym_row_product_scalar) }
    }

    /// [`Rows32::row_times_ptr`] with the AVX2 row product inlined.
    ///
    /// # Safety
    /// As [`Rows32::row_times_ptr`], and the CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn row_times_ptr_avx2(&self, p: usize, x: *const Vec3) -> Vec3 {
        // SAFETY: forwarded from the caller.
        unsafe { row_product!(self, p, x, sym_row_product_avx2) }
    }

    /// [`Rows32::row_times_ptr`] with the AVX2 row product inlined and compiled for AVX-512's
    /// 32 vector registers (the same instructions otherwise).
    ///
    /// # Safety
    /// As [`Rows32::row_times_ptr`], and the CPU must have the AVX-512 level of [`Level`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq,avx512cd")]
    #[inline]
    unsafe fn row_times_ptr_avx512(&self, p: usize, x: *const Vec3) -> Vec3 {
        // SAFETY: forwarded from the caller.
        unsafe { row_product!(self, p, x, sym_row_product_avx2) }
    }
}

/// `Σ_k values[k] · x[cols[k]]`, accumulated in double precision: one row of a
/// single-precision symmetric block matrix times a vector, the smoother's inner loop.
///
/// # Safety
/// Every `cols[k]` must index a vector of `x`; no other thread may write those vectors.
#[inline]
pub unsafe fn sym_row_product(
    values: &[Sym3f],
    cols: impl Iterator<Item = usize>,
    x: *const Vec3,
) -> Vec3 {
    #[cfg(target_arch = "x86_64")]
    if super::simd::avx2_fma() {
        // SAFETY: forwarded from the caller; the CPU has the features (checked at run time).
        return unsafe { sym_row_product_avx2(values, cols, x) };
    }
    // SAFETY: forwarded from the caller.
    unsafe { sym_row_product_scalar(values, cols, x) }
}

/// [`sym_row_product`] one component at a time (any CPU).
///
/// # Safety
/// As [`sym_row_product`].
#[inline]
pub unsafe fn sym_row_product_scalar(
    values: &[Sym3f],
    cols: impl Iterator<Item = usize>,
    x: *const Vec3,
) -> Vec3 {
    let mut acc = Vec3::zeros();
    for (v, c) in values.iter().zip(cols) {
        let xj = unsafe { *x.add(c) };
        acc += v.mul(&xj);
    }
    acc
}

/// [`sym_row_product`] with AVX2: each block's three columns are widened to four doubles (the
/// fourth lane is ignored), multiplied by the broadcast components of `x` and summed, the
/// three rows at once, with exactly the scalar form's operations in its order: the result is
/// bit-identical to [`sym_row_product_scalar`], so outputs do not depend on the CPU. (Fused
/// multiply-adds, one accumulator per column, were no faster and changed the rounding, which
/// moved a contact scene's resting state: the sphere drape's fastest vertex went from 0.027
/// to 0.059 m/s.)
///
/// # Safety
/// As [`sym_row_product`], and the CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn sym_row_product_avx2(
    values: &[Sym3f],
    cols: impl Iterator<Item = usize>,
    x: *const Vec3,
) -> Vec3 {
    use std::arch::x86_64::*;
    // SAFETY: the two loads read the block's six floats only (four, then two: a masked load
    // here was 40 % slower at 256², measured on the AMD benchmark machine); `x.add(c)` is in
    // bounds by the caller's contract and a Vec3 is three contiguous f64.
    unsafe {
        // (xx, xy, xz, yy, yz, zz): column 1 is (xy, yy, yz), column 2 (xz, yz, zz)
        let i1 = _mm256_setr_epi32(1, 3, 4, 4, 0, 0, 0, 0);
        let i2 = _mm256_setr_epi32(2, 4, 5, 5, 0, 0, 0, 0);
        let mut acc = _mm256_setzero_pd();
        for (v, c) in values.iter().zip(cols) {
            let lo = _mm_loadu_ps(v.0.as_ptr());
            let hi = _mm_castpd_ps(_mm_load_sd(v.0.as_ptr().add(4) as *const f64));
            let b = _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
            let c0 = _mm256_cvtps_pd(_mm256_castps256_ps128(b));
            let c1 = _mm256_cvtps_pd(_mm256_castps256_ps128(_mm256_permutevar8x32_ps(b, i1)));
            let c2 = _mm256_cvtps_pd(_mm256_castps256_ps128(_mm256_permutevar8x32_ps(b, i2)));
            let xp = x.add(c) as *const f64;
            // (c0 x + c1 y) + c2 z, then added: the scalar form's operations in its order
            let t = _mm256_add_pd(
                _mm256_mul_pd(c0, _mm256_broadcast_sd(&*xp)),
                _mm256_mul_pd(c1, _mm256_broadcast_sd(&*xp.add(1))),
            );
            let t = _mm256_add_pd(t, _mm256_mul_pd(c2, _mm256_broadcast_sd(&*xp.add(2))));
            acc = _mm256_add_pd(acc, t);
        }
        let mut out = [0.0f64; 4];
        _mm256_storeu_pd(out.as_mut_ptr(), acc);
        Vec3::new(out[0], out[1], out[2])
    }
}

/// The column offsets shared by the longest rows of a pattern, in their stored order, if
/// every row of that length has them: on a grid every interior row couples the same
/// neighbours, at the same distances in the numbering (13 of them for springs and bending
/// lines), so a product over such a row can compute its columns instead of reading them.
/// Empty when the longest rows differ.
pub fn grid_stencil(start: &[usize], cols: &[u32]) -> Vec<i32> {
    let rows = start.len() - 1;
    let len = (0..rows)
        .map(|p| start[p + 1] - start[p])
        .max()
        .unwrap_or(0);
    let Some(p0) = (0..rows).find(|&p| start[p + 1] - start[p] == len) else {
        return Vec::new();
    };
    let off: Vec<i32> = cols[start[p0]..start[p0 + 1]]
        .iter()
        .map(|&c| c as i32 - p0 as i32)
        .collect();
    let uniform = (0..rows).all(|p| {
        let row = &cols[start[p]..start[p + 1]];
        row.len() != len
            || row
                .iter()
                .zip(&off)
                .all(|(&c, &o)| c as i64 == p as i64 + o as i64)
    });
    if uniform {
        off
    } else {
        Vec::new()
    }
}

/// A symmetric 3×3 block in double precision: (xx, xy, xz, yy, yz, zz).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// The upper triangle of `m`.
    #[inline]
    pub fn from_upper(m: &Mat3) -> Self {
        Sym3([
            m[(0, 0)],
            m[(0, 1)],
            m[(0, 2)],
            m[(1, 1)],
            m[(1, 2)],
            m[(2, 2)],
        ])
    }

    /// `self += m · scale`, upper triangle of `m` only.
    #[inline]
    pub fn add_scaled(&mut self, m: &Mat3, scale: f64) {
        let u = Self::from_upper(m).0;
        for (a, b) in self.0.iter_mut().zip(u) {
            *a += b * scale;
        }
    }

    /// `self += m · scale`.
    #[inline]
    pub fn add_scaled_sym(&mut self, m: &Sym3, scale: f64) {
        for (a, b) in self.0.iter_mut().zip(m.0) {
            *a += b * scale;
        }
    }

    /// The full block.
    #[inline]
    pub fn to_mat3(&self) -> Mat3 {
        let [a, b, c, d, e, f] = self.0;
        Mat3::new(a, b, c, b, d, e, c, e, f)
    }

    /// The block rounded to single precision.
    #[inline]
    pub fn to_f32(&self) -> Sym3f {
        Sym3f(self.0.map(|v| v as f32))
    }

    /// `self · x`, each component summed in the order of a general block's product.
    #[inline]
    pub fn mul(&self, x: &Vec3) -> Vec3 {
        let [a, b, c, d, e, f] = self.0;
        Vec3::new(
            a * x.x + b * x.y + c * x.z,
            b * x.x + d * x.y + e * x.z,
            c * x.x + e * x.y + f * x.z,
        )
    }
}

/// 3×3 single-precision block.
pub type Mat3f = nalgebra::Matrix3<f32>;

/// A symmetric 3×3 block in single precision: (xx, xy, xz, yy, yz, zz). The multigrid
/// smoother is bound by memory traffic, and on grid cloths every block is symmetric.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sym3f(pub [f32; 6]);

impl Sym3f {
    /// The upper triangle of `m`, rounded to single precision.
    #[inline]
    pub fn from_upper(m: &Mat3) -> Self {
        Sym3f([
            m[(0, 0)] as f32,
            m[(0, 1)] as f32,
            m[(0, 2)] as f32,
            m[(1, 1)] as f32,
            m[(1, 2)] as f32,
            m[(2, 2)] as f32,
        ])
    }

    /// The block in double precision.
    #[inline]
    pub fn to_mat3(&self) -> Mat3 {
        let [a, b, c, d, e, f] = self.0.map(f64::from);
        Mat3::new(a, b, c, b, d, e, c, e, f)
    }

    /// `self · x`, accumulated in double precision.
    #[inline]
    pub fn mul(&self, x: &Vec3) -> Vec3 {
        Sym3(self.0.map(f64::from)).mul(x)
    }
}

impl Bcsr3 {
    /// Builds the symmetric pattern of an `n`-row matrix holding every diagonal block and both
    /// `(i, j)` and `(j, i)` for each pair. Columns are sorted within a row.
    pub fn with_pattern(n: usize, pairs: &[(usize, usize)]) -> Self {
        let mut adj: Vec<Vec<u32>> = (0..n).map(|i| vec![i as u32]).collect();
        for &(i, j) in pairs {
            if i != j {
                adj[i].push(j as u32);
                adj[j].push(i as u32);
            }
        }
        let mut row_ptr = Vec::with_capacity(n + 1);
        let mut cols = Vec::new();
        let mut diag = Vec::with_capacity(n);
        row_ptr.push(0);
        for (i, row) in adj.iter_mut().enumerate() {
            row.sort_unstable();
            row.dedup();
            let start = cols.len();
            diag.push(start + row.binary_search(&(i as u32)).expect("diagonal present"));
            cols.extend_from_slice(row);
            row_ptr.push(cols.len());
        }
        let values = vec![Mat3::zeros(); cols.len()];
        Bcsr3 {
            row_ptr,
            cols,
            values,
            sym: Vec::new(),
            diag,
            values32: Vec::new(),
            stencil32: Vec::new(),
            permuted: None,
        }
    }

    /// Number of block rows.
    pub fn rows(&self) -> usize {
        self.diag.len()
    }

    /// Bytes held by the matrix: pattern, double-precision blocks (general or symmetric) and
    /// the single-precision mirrors.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        let mut b = self.row_ptr.len() * size_of::<usize>()
            + self.cols.len() * size_of::<u32>()
            + self.values.len() * size_of::<Mat3>()
            + self.sym.len() * size_of::<Sym3>()
            + self.diag.len() * size_of::<usize>()
            + self.values32.len() * size_of::<Sym3f>()
            + self.stencil32.len() * size_of::<i32>();
        if let Some(p) = &self.permuted {
            b += p.order.len() * size_of::<u32>()
                + (p.start.len() + p.row_start.len() + p.diag.len()) * size_of::<usize>()
                + p.cols.len() * size_of::<u32>()
                + p.values.len() * size_of::<Sym3f>()
                + p.stencil.len() * size_of::<i32>();
        }
        b
    }

    /// Number of stored blocks.
    pub fn nnz_blocks(&self) -> usize {
        self.cols.len()
    }

    /// Index of block `(i, j)` in `values`, if it is in the pattern.
    pub fn slot(&self, i: usize, j: usize) -> Option<usize> {
        let (s, e) = (self.row_ptr[i], self.row_ptr[i + 1]);
        self.cols[s..e]
            .binary_search(&(j as u32))
            .ok()
            .map(|k| s + k)
    }

    /// `y = A x`, parallel over row chunks, bit-identical whatever the thread count.
    pub fn mul_vec(&self, x: &[Vec3], y: &mut [Vec3]) {
        y.par_chunks_mut(ROW_CHUNK).enumerate().for_each(|(c, ys)| {
            let base = c * ROW_CHUNK;
            for (k, yi) in ys.iter_mut().enumerate() {
                *yi = self.row_times(base + k, x);
            }
        });
    }

    /// Allocates the single-precision symmetric mirror (filled by whoever fills `values`;
    /// only valid when every block is symmetric, as on grid cloths).
    pub fn enable_mirror32(&mut self) {
        self.values32 = vec![Sym3f::default(); self.cols.len()];
        self.stencil32 = grid_stencil(&self.row_ptr, &self.cols);
    }

    /// Stores the double-precision blocks as symmetric blocks (`sym`) instead of general ones
    /// (`values`, emptied), with the single-precision mirror (enabled here). Only for matrices
    /// whose blocks are all symmetric (grid cloths): whoever fills the matrix keeps the upper
    /// triangles. Returns false, changing nothing, when a row has more than [`SYM_ROW_MAX`]
    /// blocks.
    pub fn store_symmetric(&mut self) -> bool {
        if !self.rows_fit_symmetric() {
            return false;
        }
        if self.values32.is_empty() {
            self.enable_mirror32();
        }
        self.sym = vec![Sym3::default(); self.cols.len()];
        self.values = Vec::new();
        true
    }

    /// Keeps no double-precision blocks at all, only the single-precision mirror (enabled
    /// here): for the coarse levels of a multigrid hierarchy, which only its smoother reads.
    /// [`Bcsr3::row_times`] and [`Bcsr3::block`] must not be used on such a matrix. Returns
    /// false, changing nothing, when a row has more than [`SYM_ROW_MAX`] blocks.
    pub fn store_single_only(&mut self) -> bool {
        if !self.rows_fit_symmetric() {
            return false;
        }
        if self.values32.is_empty() {
            self.enable_mirror32();
        }
        self.sym = Vec::new();
        self.values = Vec::new();
        true
    }

    fn rows_fit_symmetric(&self) -> bool {
        self.row_ptr.windows(2).all(|w| w[1] - w[0] <= SYM_ROW_MAX)
    }

    /// Block `k` (as stored in `values` or `sym`).
    #[inline]
    pub fn block(&self, k: usize) -> Mat3 {
        if self.sym.is_empty() {
            self.values[k]
        } else {
            self.sym[k].to_mat3()
        }
    }

    /// Allocates a second single-precision mirror whose stored row `p` is row `order[p]`
    /// (filled by whoever fills `values32`, which this enables too). Keeps an existing one
    /// with the same order.
    pub fn enable_permuted_mirror(&mut self, order: &[u32]) {
        if self.values32.is_empty() {
            self.enable_mirror32();
        }
        if self.permuted.as_ref().is_some_and(|p| p.order == order) {
            return;
        }
        assert_eq!(order.len(), self.rows(), "a permutation of the rows");
        let n = self.rows();
        let mut inverse = vec![0u32; n];
        for (p, &i) in order.iter().enumerate() {
            inverse[i as usize] = p as u32;
        }
        let mut pm = PermutedMirror {
            order: order.to_vec(),
            start: Vec::with_capacity(n + 1),
            row_start: vec![0; n],
            cols: Vec::with_capacity(self.cols.len()),
            diag: Vec::with_capacity(n),
            values: vec![Sym3f::default(); self.cols.len()],
            stencil: Vec::new(),
        };
        pm.start.push(0);
        for &i in order {
            let i = i as usize;
            let at = pm.cols.len();
            pm.row_start[i] = at;
            pm.diag.push(at + self.diag[i] - self.row_ptr[i]);
            pm.cols.extend(
                self.cols[self.row_ptr[i]..self.row_ptr[i + 1]]
                    .iter()
                    .map(|&j| inverse[j as usize]),
            );
            pm.start.push(pm.cols.len());
        }
        pm.stencil = grid_stencil(&pm.start, &pm.cols);
        self.permuted = Some(pm);
    }

    /// The single-precision mirror in row order.
    pub fn rows32(&self) -> Rows32<'_> {
        Rows32 {
            start: &self.row_ptr,
            cols: &self.cols,
            diag: &self.diag,
            values: &self.values32,
            stencil: &self.stencil32,
        }
    }

    /// Row `i` of `A x`.
    #[inline]
    pub fn row_times(&self, i: usize, x: &[Vec3]) -> Vec3 {
        #[cfg(target_arch = "x86_64")]
        match super::simd::level() {
            // SAFETY: the CPU has the features (checked at run time).
            Level::Avx512 => return unsafe { self.row_times_avx512(i, x) },
            // SAFETY: as above.
            Level::Avx2 => return unsafe { self.row_times_avx2(i, x) },
            Level::Generic => {}
        }
        self.row_times_any(i, x)
    }

    /// [`Bcsr3::row_times`] compiled for AVX2 and FMA (bit-identical: see [`super::simd`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn row_times_avx2(&self, i: usize, x: &[Vec3]) -> Vec3 {
        self.row_times_any(i, x)
    }

    /// [`Bcsr3::row_times`] compiled for AVX-512 (bit-identical: see [`super::simd`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq,avx512cd")]
    #[inline]
    fn row_times_avx512(&self, i: usize, x: &[Vec3]) -> Vec3 {
        self.row_times_any(i, x)
    }

    /// [`Bcsr3::row_times`] for whichever CPU features its caller was compiled with.
    #[inline(always)]
    pub(crate) fn row_times_any(&self, i: usize, x: &[Vec3]) -> Vec3 {
        let mut acc = Vec3::zeros();
        let (s, e) = (self.row_ptr[i], self.row_ptr[i + 1]);
        if self.sym.is_empty() {
            for k in s..e {
                acc += self.values[k] * x[self.cols[k] as usize];
            }
        } else if e - s == self.stencil32.len() {
            // a full grid row: its columns are i + the stencil's offsets (see `grid_stencil`)
            for (b, &o) in self.sym[s..e].iter().zip(&self.stencil32) {
                acc += b.mul(&x[(i as isize + o as isize) as usize]);
            }
        } else {
            for (b, &c) in self.sym[s..e].iter().zip(&self.cols[s..e]) {
                acc += b.mul(&x[c as usize]);
            }
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_matches_dense() {
        let n = 5;
        let pairs = [(0, 1), (1, 3), (4, 2), (0, 4)];
        let mut a = Bcsr3::with_pattern(n, &pairs);
        let mut dense = vec![vec![Mat3::zeros(); n]; n];
        for i in 0..n {
            for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                let j = a.cols[k] as usize;
                let m = Mat3::from_fn(|r, c| (1 + i * 7 + j * 3 + r * 2 + c) as f64 * 0.1);
                a.values[k] = m;
                dense[i][j] = m;
            }
        }
        let x: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f64, 1.0, -(i as f64) * 0.5))
            .collect();
        let mut y = vec![Vec3::zeros(); n];
        a.mul_vec(&x, &mut y);
        for i in 0..n {
            let mut e = Vec3::zeros();
            for j in 0..n {
                e += dense[i][j] * x[j];
            }
            assert!((e - y[i]).norm() < 1e-12);
        }
        assert_eq!(a.slot(2, 3), None);
        assert!(a.slot(3, 1).is_some());
    }

    #[test]
    fn permuted_mirror_holds_the_same_rows() {
        let n = 6;
        let pairs = [(0, 1), (1, 3), (4, 2), (0, 4), (5, 1)];
        let mut a = Bcsr3::with_pattern(n, &pairs);
        let order = [3u32, 0, 5, 1, 4, 2];
        a.enable_permuted_mirror(&order);
        for (k, v) in a.values32.iter_mut().enumerate() {
            *v = Sym3f([k as f32, 1.0, 2.0, 3.0, 4.0, 5.0]);
        }
        let pm = a.permuted.as_mut().expect("enabled");
        for i in 0..n {
            for s in a.row_ptr[i]..a.row_ptr[i + 1] {
                pm.values[pm.row_start[i] + s - a.row_ptr[i]] = a.values32[s];
            }
        }
        let x: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f64, 1.0, 0.5)).collect();
        // the same vector in the new numbering
        let xp: Vec<Vec3> = order.iter().map(|&i| x[i as usize]).collect();
        let pm = a.permuted.as_ref().expect("enabled");
        let rows = pm.rows();
        for (p, &i) in order.iter().enumerate() {
            let i = i as usize;
            // SAFETY: x and xp hold n vectors and nobody writes them.
            let (yp, yi) = unsafe {
                (
                    rows.row_times_ptr(p, xp.as_ptr()),
                    a.rows32().row_times_ptr(i, x.as_ptr()),
                )
            };
            assert_eq!(yp, yi);
            assert_eq!(pm.cols[pm.diag[p]] as usize, p);
            assert_eq!(rows.slot(p, p), Some(pm.diag[p]));
        }
    }
    #[test]
    fn symmetric_row_product_matches_the_scalar_form() {
        // blocks with entries of both signs and magnitudes, columns out of order
        let values: Vec<Sym3f> = (0..13)
            .map(|k| {
                let f = k as f32;
                Sym3f([1.0 + f, -0.5 * f, 0.25, 3.0 - f, 1e-3 * f, 7.0 + 0.1 * f])
            })
            .collect();
        let cols: Vec<u32> = (0..13).map(|k| (k * 5 % 13) as u32).collect();
        let x: Vec<Vec3> = (0..13)
            .map(|i| Vec3::new(i as f64 - 6.0, 0.3 * i as f64, 1.0 / (1.0 + i as f64)))
            .collect();
        // the dense product in double precision
        let mut want = Vec3::zeros();
        for (v, &c) in values.iter().zip(&cols) {
            want += v.to_mat3() * x[c as usize];
        }
        // SAFETY: every column indexes x.
        let (fast, slow) = unsafe {
            (
                sym_row_product(&values, cols.iter().map(|&c| c as usize), x.as_ptr()),
                sym_row_product_scalar(&values, cols.iter().map(|&c| c as usize), x.as_ptr()),
            )
        };
        assert!(
            (fast - want).norm() <= 1e-12 * want.norm(),
            "{fast} vs {want}"
        );
        assert!(
            (slow - want).norm() <= 1e-12 * want.norm(),
            "{slow} vs {want}"
        );
        // the vector form rounds exactly as the scalar one: outputs do not depend on the CPU
        assert_eq!(fast.map(f64::to_bits), slow.map(f64::to_bits));
    }

    /// Pairs of a 5-point-plus-bending grid pattern on an nx × ny grid.
    fn grid_pairs(nx: usize, ny: usize) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for i in 0..ny {
            for j in 0..nx {
                let p = i * nx + j;
                for (di, dj) in [(0, 1), (0, 2), (1, 0), (2, 0), (1, 1)] {
                    if i + di < ny && j + dj < nx {
                        pairs.push((p, (i + di) * nx + j + dj));
                    }
                }
                if i + 1 < ny && j >= 1 {
                    pairs.push((p, (i + 1) * nx + j - 1));
                }
            }
        }
        pairs
    }

    #[test]
    fn grid_rows_read_their_columns_from_the_stencil() {
        let (nx, ny) = (7, 6);
        let mut a = Bcsr3::with_pattern(nx * ny, &grid_pairs(nx, ny));
        a.enable_mirror32();
        assert_eq!(a.stencil32.len(), 13);
        let nx = nx as i32;
        let expect = [
            -2 * nx,
            -nx - 1,
            -nx,
            -nx + 1,
            -2,
            -1,
            0,
            1,
            2,
            nx - 1,
            nx,
            nx + 1,
            2 * nx,
        ];
        assert_eq!(a.stencil32, expect);
        for (k, v) in a.values32.iter_mut().enumerate() {
            let f = k as f32;
            *v = Sym3f([1.0 + f, 0.5 - f, 0.25 * f, 2.0, -f, 3.0 + 0.5 * f]);
        }
        let x: Vec<Vec3> = (0..a.rows())
            .map(|i| Vec3::new(i as f64, 1.0 - i as f64, 0.5 * i as f64))
            .collect();
        let rows = a.rows32();
        let mut full = 0;
        for p in 0..a.rows() {
            let (s, e) = (a.row_ptr[p], a.row_ptr[p + 1]);
            full += usize::from(e - s == 13);
            let cols = a.cols[s..e].iter().map(|&c| c as usize);
            // SAFETY: x holds one vector per row and nobody writes it.
            let (by_rows, by_cols) = unsafe {
                (
                    rows.row_times_ptr(p, x.as_ptr()),
                    sym_row_product_scalar(&a.values32[s..e], cols, x.as_ptr()),
                )
            };
            assert_eq!(by_rows, by_cols, "row {p}");
        }
        assert_eq!(full, 3 * 2, "interior rows of a 7 × 6 grid");
    }

    #[test]
    fn no_stencil_when_the_longest_rows_differ() {
        // every row has two blocks: row 0 at offsets (0, 3), row 1 at (0, 1)
        let a = Bcsr3::with_pattern(4, &[(0, 3), (2, 1)]);
        assert!(grid_stencil(&a.row_ptr, &a.cols).is_empty());
        // a chain: rows 1 and 2 couple both neighbours
        let b = Bcsr3::with_pattern(4, &[(0, 1), (1, 2), (2, 3)]);
        assert_eq!(grid_stencil(&b.row_ptr, &b.cols), vec![-1, 0, 1]);
    }
}
