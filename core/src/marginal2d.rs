//! Tabulated conditional 2D warps: a density on the unit square given by a table
//! per node of a parameter grid, sampled *exactly* at any parameter between the
//! nodes (the idea of Mitsuba 3's `Marginal2D<Dim>` and pbrt-v4's
//! `PiecewiseLinear2D<Dim>`).
//!
//! **Tables.** Each node's table holds the density's values at the `nx x ny`
//! vertices `(i / (nx - 1), j / (ny - 1))` of a grid on `[0,1]^2`; between vertices
//! the density is the bilinear interpolant. [`tabulate`] normalizes each table to
//! integrate to 1 and stores beside it two cumulative tables, exact for the
//! bilinear interpolant: per vertex row `j`, `C_j(x_i) = ∫_0^{x_i} f(x, y_j) dx`
//! (the trapezoid rule is exact on linear pieces), and the marginal
//! `M(y_j) = ∫_0^{y_j} ∫_0^1 f(x, y) dx dy` (the row integral is linear in `y`
//! between vertex rows).
//!
//! **Blends.** A query's parameters select a [`Blend`]: at most `2^3` node tables
//! with convex weights (multilinear between the nodes of a regular grid,
//! [`Blend::multilinear`], or any weights the caller computes, e.g. wrapping
//! around a sphere). Values and both cumulative tables are linear in the data, so
//! the blend's cumulative tables are the blends of the nodes' ones and cost
//! `O(2^d)` per lookup.
//!
//! **The warp** ([`Marginal2D::sample`]) inverts the blend's marginal CDF in `y`,
//! then its conditional CDF in `x` at that `y`, each a quadratic within one cell
//! (the density is linear along each axis there), found by binary search: work
//! `O(2^d (log nx + log ny))` per sample, no allocation, no panic.
//! [`Marginal2D::pdf`] is the blend's bilinear value over its total mass: *exactly*
//! the density of the points `sample` returns (up to rounding), not an
//! approximation of it. [`Marginal2D::invert`] is `sample`'s inverse.

use crate::real::{clamp_unit, Real};

/// Most parameter dimensions of a warp (a blend has at most `2^3` nodes).
pub const MAX_PARAMS: usize = 3;

/// Most nodes in one blend: `2^MAX_PARAMS`.
pub const MAX_BLEND: usize = 1 << MAX_PARAMS;

/// The sizes of a warp: vertices per table axis and the number of node tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Marginal2DShape {
    /// Vertices per axis of each table, `[nx, ny]`, each at least 2.
    pub size: [u32; 2],
    /// Node tables, at least 1.
    pub nodes: u32,
}

impl Marginal2DShape {
    /// Values per table, `nx ny` (`None` on overflow).
    pub fn table_len(&self) -> Option<usize> {
        (self.size[0] as usize).checked_mul(self.size[1] as usize)
    }

    /// Length of the data and of the conditional CDFs: `nodes nx ny`.
    pub fn data_len(&self) -> Option<usize> {
        self.table_len()?.checked_mul(self.nodes as usize)
    }

    /// Length of the marginal CDFs: `nodes ny`.
    pub fn marginal_len(&self) -> Option<usize> {
        (self.size[1] as usize).checked_mul(self.nodes as usize)
    }
}

/// Why tables were refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marginal2DError {
    /// A table axis has fewer than 2 vertices, or there is no node.
    Shape,
    /// A slice's length is not the shape's (`data`, `marginal`, `conditional`).
    Length {
        /// Which slice: 0 data, 1 marginal, 2 conditional.
        slice: u8,
        /// Length the shape asks for (`u64::MAX` if it overflows).
        expected: u64,
        /// Length given.
        got: u64,
    },
    /// A value is negative, NaN or infinite (index into its slice).
    BadValue {
        /// Which slice: 0 data, 1 marginal, 2 conditional.
        slice: u8,
        /// Index of the value.
        index: u64,
    },
    /// A cumulative table decreases (index into its slice).
    Decreasing {
        /// Which slice: 1 marginal, 2 conditional.
        slice: u8,
        /// Index of the value below its predecessor.
        index: u64,
    },
    /// A node's table has no mass (or its mass is not finite).
    NoMass {
        /// The node.
        node: u32,
    },
}

impl core::fmt::Display for Marginal2DError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        const SLICES: [&str; 4] = ["data", "marginal CDF", "conditional CDF", "masses"];
        let name = |s: u8| SLICES.get(s as usize).copied().unwrap_or("table");
        match *self {
            Self::Shape => write!(f, "a warp table needs at least 2 x 2 vertices and 1 node"),
            Self::Length {
                slice,
                expected,
                got,
            } => write!(f, "warp {}: {got} values, expected {expected}", name(slice)),
            Self::BadValue { slice, index } => {
                write!(
                    f,
                    "warp {} value {index} is negative or not finite",
                    name(slice)
                )
            }
            Self::Decreasing { slice, index } => {
                write!(f, "warp {} decreases at {index}", name(slice))
            }
            Self::NoMass { node } => write!(f, "warp node {node} has no mass"),
        }
    }
}

impl core::error::Error for Marginal2DError {}

/// Node tables with convex weights: what a query's parameters select.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend<T> {
    nodes: [u32; MAX_BLEND],
    weights: [T; MAX_BLEND],
    len: usize,
}

impl<T: Real> Blend<T> {
    /// Node `node` alone (weight 1).
    pub fn single(node: u32) -> Self {
        let mut b = Self::empty();
        b.push(node, T::ONE);
        b
    }

    /// The multilinear blend on a regular grid of `counts[k]` nodes over `[0, 1]`
    /// per parameter `k` (node `(i_0, i_1, i_2)` is table `i_0 + counts[0] (i_1 +
    /// counts[1] i_2)`): each parameter clamped into `[0, 1]` (NaN is 0) and
    /// weighted between its two neighbouring nodes. At most [`MAX_PARAMS`]
    /// parameters are read (`params` and `counts` pair up, the shorter decides); a
    /// count of 0 or 1 pins its parameter to node 0. Exactly a node's table at
    /// the node.
    pub fn multilinear(params: &[T], counts: &[u32]) -> Self {
        let d = params.len().min(counts.len()).min(MAX_PARAMS);
        // Per axis the lower node's share of the table index and the upper's
        // step and both weights; an axis past `d` or of one node keeps the
        // lower node at weight 1 (and its upper corners weigh 0).
        let mut base = 0u32;
        let mut step = [0u32; MAX_PARAMS];
        let mut weights = [[T::ONE, T::ZERO]; MAX_PARAMS];
        let mut s = 1u32;
        for k in 0..d {
            let c = counts[k].max(1);
            if c >= 2 {
                let pos = clamp_unit(params[k]) * T::of((c - 1) as f64);
                // `pos >= 0`, so truncation is the floor (without a call to libm's).
                let i = (pos.to_f64() as u32).min(c - 2);
                let frac = pos - T::of(i as f64);
                base = base.saturating_add(i.saturating_mul(s));
                step[k] = s;
                weights[k] = [T::ONE - frac, frac];
            }
            s = s.saturating_mul(c);
        }
        // Every corner of the cube, in the order of its bits (those past `d`
        // weigh 0): fixed trip counts, so the loops unroll.
        let mut b = Self::empty();
        for corner in 0..MAX_BLEND {
            let mut node = base;
            let mut w = T::ONE;
            for k in 0..MAX_PARAMS {
                let up = (corner >> k) & 1;
                node = node.saturating_add(step[k] * up as u32);
                w = w * weights[k][up];
            }
            if w > T::ZERO {
                b.push(node, w);
            }
        }
        if b.len == 0 {
            b.push(0, T::ONE);
        }
        b
    }

    /// The blend of `(node, weight)` pairs (at most [`MAX_BLEND`]; the rest are
    /// ignored), negative or NaN weights read as 0; the caller makes them sum to
    /// 1 (the warp divides by the blend's mass, so any positive sum samples the
    /// same density).
    pub fn from_pairs(pairs: &[(u32, T)]) -> Self {
        let mut b = Self::empty();
        for &(node, w) in pairs.iter().take(MAX_BLEND) {
            b.push(node, if w > T::ZERO { w } else { T::ZERO });
        }
        b
    }

    /// The `(node, weight)` pairs.
    pub fn pairs(&self) -> impl Iterator<Item = (u32, T)> + '_ {
        self.nodes[..self.len]
            .iter()
            .copied()
            .zip(self.weights[..self.len].iter().copied())
    }

    fn empty() -> Self {
        Self {
            nodes: [0; MAX_BLEND],
            weights: [T::ZERO; MAX_BLEND],
            len: 0,
        }
    }

    fn push(&mut self, node: u32, w: T) {
        if self.len < MAX_BLEND {
            self.nodes[self.len] = node;
            self.weights[self.len] = w;
            self.len += 1;
        }
    }
}

/// Normalizes each node's table of `data` in place (its bilinear interpolant
/// integrates to 1 over `[0,1]^2`) and fills `marginal` and `conditional` with its
/// cumulative tables (module docs), all in `T`'s arithmetic. The layout: node
/// `k`'s vertex `(i, j)` is `data[(k ny + j) nx + i]` and `conditional[...]` at the
/// same index; its marginal at row `j` is `marginal[k ny + j]`.
pub fn tabulate<T: Real>(
    shape: Marginal2DShape,
    data: &mut [T],
    marginal: &mut [T],
    conditional: &mut [T],
) -> Result<(), Marginal2DError> {
    tabulate_into(shape, data, marginal, conditional, None)
}

/// [`tabulate`], and each node's mass before normalization (the integral of its
/// bilinear interpolant, what the tables are divided by) written to `masses`,
/// one per node (a length error names it as slice 3).
pub fn tabulate_with_masses<T: Real>(
    shape: Marginal2DShape,
    data: &mut [T],
    marginal: &mut [T],
    conditional: &mut [T],
    masses: &mut [T],
) -> Result<(), Marginal2DError> {
    if masses.len() != shape.nodes as usize {
        return Err(Marginal2DError::Length {
            slice: 3,
            expected: shape.nodes as u64,
            got: masses.len() as u64,
        });
    }
    tabulate_into(shape, data, marginal, conditional, Some(masses))
}

fn tabulate_into<T: Real>(
    shape: Marginal2DShape,
    data: &mut [T],
    marginal: &mut [T],
    conditional: &mut [T],
    mut masses: Option<&mut [T]>,
) -> Result<(), Marginal2DError> {
    check_lengths(shape, data.len(), marginal.len(), conditional.len())?;
    if let Some(index) = data.iter().position(|&v| !(v >= T::ZERO && v.is_finite())) {
        return Err(Marginal2DError::BadValue {
            slice: 0,
            index: index as u64,
        });
    }
    let (nx, ny) = (shape.size[0] as usize, shape.size[1] as usize);
    let half_dx = T::of(0.5) / T::of((nx - 1) as f64);
    let half_dy = T::of(0.5) / T::of((ny - 1) as f64);
    for k in 0..shape.nodes as usize {
        let table = k * nx * ny;
        for j in 0..ny {
            let row = table + j * nx;
            conditional[row] = T::ZERO;
            for i in 1..nx {
                conditional[row + i] =
                    conditional[row + i - 1] + half_dx * (data[row + i - 1] + data[row + i]);
            }
        }
        let m = k * ny;
        marginal[m] = T::ZERO;
        for j in 1..ny {
            let r0 = conditional[table + j * nx - 1];
            let r1 = conditional[table + (j + 1) * nx - 1];
            marginal[m + j] = marginal[m + j - 1] + half_dy * (r0 + r1);
        }
        let total = marginal[m + ny - 1];
        if !(total > T::ZERO && total.is_finite()) {
            return Err(Marginal2DError::NoMass { node: k as u32 });
        }
        if let Some(slot) = masses.as_deref_mut().and_then(|m| m.get_mut(k)) {
            *slot = total;
        }
        let inv = T::ONE / total;
        for v in &mut data[table..table + nx * ny] {
            *v = *v * inv;
        }
        for v in &mut conditional[table..table + nx * ny] {
            *v = *v * inv;
        }
        for v in &mut marginal[m..m + ny] {
            *v = *v * inv;
        }
    }
    Ok(())
}

fn check_lengths(
    shape: Marginal2DShape,
    data: usize,
    marginal: usize,
    conditional: usize,
) -> Result<(), Marginal2DError> {
    if shape.size[0] < 2 || shape.size[1] < 2 || shape.nodes == 0 {
        return Err(Marginal2DError::Shape);
    }
    let want = |n: Option<usize>| n.map_or(u64::MAX, |n| n as u64);
    for (slice, expected, got) in [
        (0u8, want(shape.data_len()), data),
        (1, want(shape.marginal_len()), marginal),
        (2, want(shape.data_len()), conditional),
    ] {
        if expected != got as u64 {
            return Err(Marginal2DError::Length {
                slice,
                expected,
                got: got as u64,
            });
        }
    }
    Ok(())
}

/// `$warp.$method($arg, &picked)` with `blend`'s nodes picked into the
/// slots of its size ([`Marginal2D::pick`]): 1, 2, 4 (for 3 or 4 nodes) or
/// [`MAX_BLEND`].
macro_rules! by_blend_size {
    ($warp:ident, $blend:ident, $method:ident($arg:ident)) => {
        match $warp.picked_len($blend) {
            0 | 1 => $warp.$method($arg, &$warp.pick::<1>($blend)),
            2 => $warp.$method($arg, &$warp.pick::<2>($blend)),
            3 | 4 => $warp.$method($arg, &$warp.pick::<4>($blend)),
            _ => $warp.$method($arg, &$warp.pick::<MAX_BLEND>($blend)),
        }
    };
}

/// A tabulated conditional 2D warp over borrowed tables (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct Marginal2D<'a, T> {
    nx: usize,
    ny: usize,
    nodes: usize,
    data: &'a [T],
    marginal: &'a [T],
    conditional: &'a [T],
}

impl<'a, T: Real> Marginal2D<'a, T> {
    /// The warp over tables laid out as [`tabulate`] writes them. Checks, in order:
    /// the shape; the three lengths; every value finite and non-negative; each
    /// cumulative row and each marginal non-decreasing; each node's mass positive.
    /// `O(nodes nx ny)`, once. Tables that pass but were not written by
    /// [`tabulate`] still never make the warp panic; its pdf is then only as exact
    /// as they are consistent.
    pub fn new(
        shape: Marginal2DShape,
        data: &'a [T],
        marginal: &'a [T],
        conditional: &'a [T],
    ) -> Result<Self, Marginal2DError> {
        check_lengths(shape, data.len(), marginal.len(), conditional.len())?;
        for (slice, values) in [(0u8, data), (1, marginal), (2, conditional)] {
            if let Some(index) = values
                .iter()
                .position(|&v| !(v >= T::ZERO && v.is_finite()))
            {
                return Err(Marginal2DError::BadValue {
                    slice,
                    index: index as u64,
                });
            }
        }
        let (nx, ny) = (shape.size[0] as usize, shape.size[1] as usize);
        for (slice, values, run) in [(1u8, marginal, ny), (2, conditional, nx)] {
            for (r, chunk) in values.chunks(run).enumerate() {
                if let Some(i) = chunk.windows(2).position(|w| w[1] < w[0]) {
                    return Err(Marginal2DError::Decreasing {
                        slice,
                        index: (r * run + i + 1) as u64,
                    });
                }
            }
        }
        for (node, m) in marginal.chunks(ny).enumerate() {
            if !positive(m[ny - 1]) {
                return Err(Marginal2DError::NoMass { node: node as u32 });
            }
        }
        Ok(Self {
            nx,
            ny,
            nodes: shape.nodes as usize,
            data,
            marginal,
            conditional,
        })
    }

    /// The warp over tables whose values [`Self::new`] has checked before (a
    /// blob's, validated once at parse): checks the shape and the three lengths
    /// only, `O(1)`. Never panics on any values; the pdf is as exact as the
    /// tables are consistent.
    pub fn view(
        shape: Marginal2DShape,
        data: &'a [T],
        marginal: &'a [T],
        conditional: &'a [T],
    ) -> Result<Self, Marginal2DError> {
        check_lengths(shape, data.len(), marginal.len(), conditional.len())?;
        Ok(Self {
            nx: shape.size[0] as usize,
            ny: shape.size[1] as usize,
            nodes: shape.nodes as usize,
            data,
            marginal,
            conditional,
        })
    }

    /// `blend`'s nodes that have tables, with their offsets (module docs' layout),
    /// worked out once per query rather than at each of its ~35 table reads,
    /// in `N` slots: the nodes first (the first `N` of them, callers pass
    /// `N >=` [`Self::picked_len`]), then empty slots ([`NO_TABLE`], which read
    /// as nothing).
    #[inline]
    fn pick<const N: usize>(&self, blend: &Blend<T>) -> Picked<T, N> {
        let mut p = Picked {
            weight: [T::ZERO; N],
            table: [NO_TABLE; N],
            marginal: [NO_TABLE; N],
        };
        let mut len = 0;
        for (node, w) in blend.pairs() {
            let node = node as usize;
            if node < self.nodes && len < N {
                p.weight[len] = w;
                p.table[len] = node * self.nx * self.ny;
                p.marginal[len] = node * self.ny;
                len += 1;
            }
        }
        p
    }

    /// The number of `blend`'s nodes that have tables.
    #[inline]
    fn picked_len(&self, blend: &Blend<T>) -> usize {
        blend
            .pairs()
            .filter(|&(node, _)| (node as usize) < self.nodes)
            .count()
    }

    #[inline(always)]
    fn m<const N: usize>(&self, j: usize, p: &Picked<T, N>) -> T {
        p.blended(self.marginal, &p.marginal, j)
    }

    #[inline(always)]
    fn c<const N: usize>(&self, j: usize, i: usize, p: &Picked<T, N>) -> T {
        p.blended(self.conditional, &p.table, j * self.nx + i)
    }

    #[inline(always)]
    fn f<const N: usize>(&self, j: usize, i: usize, p: &Picked<T, N>) -> T {
        p.blended(self.data, &p.table, j * self.nx + i)
    }

    /// The blended conditional CDF at vertex `i` of the row at `y = (j + t) dy`.
    #[inline(always)]
    fn c_at<const N: usize>(&self, j: usize, t: T, i: usize, p: &Picked<T, N>) -> T {
        (T::ONE - t) * self.c(j, i, p) + t * self.c(j + 1, i, p)
    }

    /// The blended density at vertex `i` of the row at `y = (j + t) dy`.
    #[inline(always)]
    fn f_at<const N: usize>(&self, j: usize, t: T, i: usize, p: &Picked<T, N>) -> T {
        (T::ONE - t) * self.f(j, i, p) + t * self.f(j + 1, i, p)
    }

    /// The blended densities at the corners `(j, i), (j, i + 1), (j + 1, i),
    /// (j + 1, i + 1)` of cell `(i, j)`.
    #[inline(always)]
    fn corners<const N: usize>(&self, i: usize, j: usize, p: &Picked<T, N>) -> [T; 4] {
        [(j, i), (j, i + 1), (j + 1, i), (j + 1, i + 1)].map(|(b, a)| self.f(b, a, p))
    }

    /// Draws the point at primary sample `u` in `[0,1]^2` from the blend's
    /// density and returns it with its density ([`Self::pdf`]). `u` outside the
    /// square is clamped into it (NaN as 0).
    pub fn sample(&self, u: [T; 2], blend: &Blend<T>) -> ([T; 2], T) {
        // One copy per blend size, whose sums over the nodes unroll and whose
        // weights stay in registers: the warp is bound by its ~35 blended
        // reads. A blend of 3 nodes takes 4 slots, the last adding 0.
        by_blend_size!(self, blend, sample_picked(u))
    }

    #[inline(always)]
    fn sample_picked<const N: usize>(&self, u: [T; 2], blend: &Picked<T, N>) -> ([T; 2], T) {
        let (nx, ny) = (self.nx, self.ny);
        let total = self.m(ny - 1, blend);
        // y: the marginal, then the quadratic within the row interval.
        let target = clamp_unit(u[1]) * total;
        let (j, m_j) = search(ny, target, |j| self.m(j, blend));
        let dy = T::ONE / T::of((ny - 1) as f64);
        let (r0, r1) = (self.c(j, nx - 1, blend), self.c(j + 1, nx - 1, blend));
        let t = solve_linear(r0 * dy, r1 * dy, target - m_j);
        let y = (T::of(j as f64) + t) * dy;
        // x: the conditional CDF of the row at y, then the quadratic in the cell
        // (`c_at` and `f_at` written out, to keep the values they read).
        let row_total = (T::ONE - t) * r0 + t * r1;
        let (x, corners) = if row_total > T::ZERO {
            let target = clamp_unit(u[0]) * row_total;
            let (i, c_i) = search(nx, target, |i| self.c_at(j, t, i, blend));
            let dx = T::ONE / T::of((nx - 1) as f64);
            let f = self.corners(i, j, blend);
            let g0 = (T::ONE - t) * f[0] + t * f[2];
            let g1 = (T::ONE - t) * f[1] + t * f[3];
            let s = solve_linear(g0 * dx, g1 * dx, target - c_i);
            ((T::of(i as f64) + s) * dx, Some(((i, j), f)))
        } else {
            // A row without mass (only at a row interval's end): any x, density 0.
            (clamp_unit(u[0]), None)
        };
        let p = [x.min(T::ONE), y.min(T::ONE)];
        (p, self.pdf_known(p, blend, total, corners))
    }

    /// [`Self::sample`] (the same point and density) and the point's slopes
    /// `[dx/du.x, dx/du.y, dy/du.y]` (`y` comes from the marginal alone, so
    /// `dy/du.x = 0`), exact within the table cell the point falls in. With `M`
    /// the blend's mass, `r(y)` its row mass at `y`, `f(x, y)` its bilinear
    /// density and `C(x, y)` its conditional CDF (`C(x, y) = u.x r(y)`):
    /// `dy/du.y = M / r(y)`, `dx/du.x = r(y) / f(x, y)`, `dx/du.y = (u.x r'(y) -
    /// ∂C/∂y) / f(x, y) dy/du.y`. All 0 where `r(y)` or `f(x, y)` is 0. What a
    /// trainer chains its gradients through: one warp instead of the five of
    /// central differences.
    pub fn sample_with_slopes(&self, u: [T; 2], blend: &Blend<T>) -> ([T; 2], T, [T; 3]) {
        by_blend_size!(self, blend, sample_with_slopes_picked(u))
    }

    fn sample_with_slopes_picked<const N: usize>(
        &self,
        u: [T; 2],
        blend: &Picked<T, N>,
    ) -> ([T; 2], T, [T; 3]) {
        let (p, pdf) = self.sample_picked(u, blend);
        let (nx, ny) = (self.nx, self.ny);
        let (i, s) = cell(p[0], nx);
        let (j, t) = cell(p[1], ny);
        let dx = T::ONE / T::of((nx - 1) as f64);
        let dy = T::ONE / T::of((ny - 1) as f64);
        let (r0, r1) = (self.c(j, nx - 1, blend), self.c(j + 1, nx - 1, blend));
        let row = (T::ONE - t) * r0 + t * r1;
        let f = self.corners(i, j, blend);
        let g = bilinear(f, s, t);
        if !(positive(row) && positive(g)) {
            return (p, pdf, [T::ZERO; 3]);
        }
        let dy_duy = self.m(ny - 1, blend) / row;
        // The row CDFs at x of the cell's two rows; C(x, y) blends them by t.
        let lower = self.c(j, i, blend) + linear_integral(f[0] * dx, f[1] * dx, s);
        let upper = self.c(j + 1, i, blend) + linear_integral(f[2] * dx, f[3] * dx, s);
        let dx_dy = (clamp_unit(u[0]) * (r1 - r0) - (upper - lower)) / (dy * g);
        (p, pdf, [row / g, dx_dy * dy_duy, dy_duy])
    }

    /// The density at `p` in `[0,1]^2` (clamped into it) of the points
    /// [`Self::sample`] draws: the blend's bilinear value over the blend's mass
    /// (per unit area of the square).
    pub fn pdf(&self, p: [T; 2], blend: &Blend<T>) -> T {
        by_blend_size!(self, blend, pdf_picked(p))
    }

    #[inline(always)]
    fn pdf_picked<const N: usize>(&self, p: [T; 2], blend: &Picked<T, N>) -> T {
        self.pdf_known(p, blend, self.m(self.ny - 1, blend), None)
    }

    /// [`Self::pdf`] given the blend's mass `total` and, where the caller has
    /// them, the blended densities at the corners `(j, i), (j, i + 1), (j + 1,
    /// i), (j + 1, i + 1)` of cell `(i, j)`: the same values, read once.
    #[inline(always)]
    fn pdf_known<const N: usize>(
        &self,
        p: [T; 2],
        blend: &Picked<T, N>,
        total: T,
        corners: Option<((usize, usize), [T; 4])>,
    ) -> T {
        if !positive(total) {
            return T::ZERO;
        }
        let (i, s) = cell(p[0], self.nx);
        let (j, t) = cell(p[1], self.ny);
        let f = match corners {
            Some((at, f)) if at == (i, j) => f,
            _ => self.corners(i, j, blend),
        };
        bilinear(f, s, t) / total
    }

    /// The primary sample that [`Self::sample`] maps to `p` (clamped into the
    /// square): the blend's marginal CDF at `p.y` and its conditional CDF at `p.x`.
    pub fn invert(&self, p: [T; 2], blend: &Blend<T>) -> [T; 2] {
        by_blend_size!(self, blend, invert_picked(p))
    }

    #[inline(always)]
    fn invert_picked<const N: usize>(&self, p: [T; 2], blend: &Picked<T, N>) -> [T; 2] {
        let (nx, ny) = (self.nx, self.ny);
        let total = self.m(ny - 1, blend);
        if !positive(total) {
            return [clamp_unit(p[0]), clamp_unit(p[1])];
        }
        let (j, t) = cell(p[1], ny);
        let dy = T::ONE / T::of((ny - 1) as f64);
        let (r0, r1) = (self.c(j, nx - 1, blend), self.c(j + 1, nx - 1, blend));
        let uy = (self.m(j, blend) + linear_integral(r0 * dy, r1 * dy, t)) / total;
        let row_total = self.c_at(j, t, nx - 1, blend);
        let ux = if row_total > T::ZERO {
            let (i, s) = cell(p[0], nx);
            let dx = T::ONE / T::of((nx - 1) as f64);
            let (g0, g1) = (self.f_at(j, t, i, blend), self.f_at(j, t, i + 1, blend));
            (self.c_at(j, t, i, blend) + linear_integral(g0 * dx, g1 * dx, s)) / row_total
        } else {
            clamp_unit(p[0])
        };
        [clamp_unit(ux), clamp_unit(uy)]
    }
}

/// The offset of an empty [`Picked`] slot: past every table, so that its reads
/// find nothing and add nothing (and `NO_TABLE + at` cannot overflow for any
/// index of a table that fits in memory).
const NO_TABLE: usize = usize::MAX / 2;

/// A blend's nodes that have tables, in `N` slots: weights and the offsets of
/// their tables (`node nx ny`) and marginals (`node ny`), in the blend's
/// order, then empty slots ([`NO_TABLE`], weight 0).
struct Picked<T, const N: usize> {
    weight: [T; N],
    table: [usize; N],
    marginal: [usize; N],
}

impl<T: Real, const N: usize> Picked<T, N> {
    /// `Σ weight values[offset + at]` over the slots (an offset past `values`
    /// counts as 0: empty slots; tables of checked lengths never are), summed
    /// pairwise: `log2 N` additions deep instead of `N`, which is what a
    /// search step waits for. `N` is a power of two (the warp's dispatch); the
    /// order of the sums depends only on `N`, so every caller of a blend of a
    /// given size rounds alike.
    #[inline(always)]
    fn blended(&self, values: &[T], offsets: &[usize; N], at: usize) -> T {
        let mut terms = [T::ZERO; N];
        for k in 0..N {
            if let Some(&v) = values.get(offsets[k] + at) {
                terms[k] = self.weight[k] * v;
            }
        }
        let mut width = N;
        while width > 1 {
            width /= 2;
            for k in 0..width {
                terms[k] = terms[2 * k] + terms[2 * k + 1];
            }
        }
        terms[0]
    }
}

/// The bilinear value at `(s, t)` in a cell of corner values `f` (in
/// [`Marginal2D::corners`]' order): along `x` on both rows, then between them.
#[inline(always)]
fn bilinear<T: Real>(f: [T; 4], s: T, t: T) -> T {
    let lo = (T::ONE - s) * f[0] + s * f[1];
    let hi = (T::ONE - s) * f[2] + s * f[3];
    (T::ONE - t) * lo + t * hi
}

/// Whether `x > 0` (false for NaN).
fn positive<T: Real>(x: T) -> bool {
    x > T::ZERO
}

/// The cell of `x` (clamped into `[0, 1]`) on `n` vertices and the position in it,
/// `(k, s)` with `x = (k + s) / (n - 1)`, `k <= n - 2`.
fn cell<T: Real>(x: T, n: usize) -> (usize, T) {
    let pos = clamp_unit(x) * T::of((n - 1) as f64);
    // `pos >= 0`, so truncation is the floor.
    let k = (pos.to_f64() as usize).min(n - 2);
    (k, clamp_unit(pos - T::of(k as f64)))
}

/// The interval `k` in `0..n-1` with `cdf(k) <= target < cdf(k + 1)` of a
/// non-decreasing `cdf` on `n` vertices, skipping intervals without mass (the
/// last such interval at or below `target`; interval 0 if none has mass there),
/// and `cdf(k)`.
fn search<T: Real>(n: usize, target: T, cdf: impl Fn(usize) -> T) -> (usize, T) {
    // The largest k in 0..=n-2 with cdf(k) <= target (0 if none), without
    // branches on the values. (A four-way search, three independent reads a
    // step and half as many steps, measured faster for a single node's table
    // but slower for blends of 4 and 8, whose reads fill the machine.)
    let (mut k, mut len) = (0usize, n - 1);
    while len > 1 {
        let half = len / 2;
        k += half * usize::from(cdf(k + half) <= target);
        len -= half;
    }
    let (below, above) = (cdf(k), cdf(k + 1));
    if above > below {
        // The interval has mass: the common case, and the moves below would
        // not start.
        return (k, below);
    }
    // Move off an interval without mass: down while the interval is empty (a
    // target at the top of the CDF), up while it is empty (a target at 0).
    while k > 0 && cdf(k + 1) <= cdf(k) {
        k -= 1;
    }
    while k + 2 < n && cdf(k + 1) <= cdf(k) {
        k += 1;
    }
    (k, cdf(k))
}

/// `∫_0^s (a + (b - a) r) dr = a s + (b - a) s^2 / 2`: the mass below `s` of a
/// linear density with ends `a` and `b` on `[0, 1]`.
fn linear_integral<T: Real>(a: T, b: T, s: T) -> T {
    a * s + T::of(0.5) * (b - a) * s * s
}

/// The `s` in `[0, 1]` with [`linear_integral`]`(a, b, s) = v`, for `a, b >= 0`:
/// `s = 2 v / (a + sqrt(a^2 + 2 (b - a) v))`, the root without cancellation
/// (pbrt's `SampleLinear` in its stable form); 0 where the interval has no mass.
fn solve_linear<T: Real>(a: T, b: T, v: T) -> T {
    let v = v.max(T::ZERO);
    let disc = (a * a + T::of(2.0) * (b - a) * v).max(T::ZERO);
    let den = a + disc.sqrt();
    if den > T::ZERO {
        clamp_unit(T::of(2.0) * v / den)
    } else {
        T::ZERO
    }
}

#[cfg(test)]
mod tests;
