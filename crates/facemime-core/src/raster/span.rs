//! Which pixels a triangle covers, one horizontal span per scan line.
//!
//! Vertices are snapped to 1/256 pixel and every coverage decision is an exact integer edge
//! function test at the pixel centre (pixel centres are integer coordinates). A pixel centre that
//! falls exactly on an edge is given to the triangle that contains a point displaced from it by an
//! infinitesimal step right (and, for horizontal edges, down): so triangles that share an edge
//! cover every pixel of their union exactly once, with no cracks and no double writes.

/// Sub-pixel steps per pixel of the snapped vertex coordinates.
const SUB: i64 = 256;
/// Vertices farther than this many pixels outside the target are clipped away geometrically
/// first, which keeps every edge-function product inside `i64`.
const GUARD: f64 = 65_536.0;

/// E(px, py) = a·px + b·py + c for pixel centre (px, py); inside when >= 0 (ties pre-broken).
#[derive(Clone, Copy)]
struct Edge {
    a: i64,
    b: i64,
    c: i64,
}

impl Edge {
    /// Edge from p0 to p1 (snapped coordinates) of a triangle whose interior lies on its
    /// non-negative side.
    fn new(p0: (i64, i64), p1: (i64, i64)) -> Self {
        let (dx, dy) = (p1.0 - p0.0, p1.1 - p0.1);
        // E = (X - x0)·dy - (Y - y0)·dx with X = SUB·px, Y = SUB·py.
        let mut c = p0.1 * dx - p0.0 * dy;
        // Tie-break: owned if E grows towards +x (or, when flat, towards +y).
        let owns = dy > 0 || (dy == 0 && dx < 0);
        if !owns {
            c -= 1; // E > 0 strictly, as E is an integer
        }
        Self {
            a: SUB * dy,
            b: -SUB * dx,
            c,
        }
    }
}

/// ceil(n / d) for d > 0, exactly, stepped from row to row without division: the numerator
/// grows by `dn` per row and the state keeps n = d·x - s with 0 <= s < d.
struct CeilStepper {
    x: i64,
    s: i64,
    d: i64,
    dq: i64,
    dr: i64,
}

impl CeilStepper {
    fn new(n: i64, d: i64, dn: i64) -> Self {
        let x = -((-n).div_euclid(d));
        Self {
            x,
            s: d * x - n,
            d,
            dq: dn.div_euclid(d),
            dr: dn.rem_euclid(d),
        }
    }

    /// A stepper whose value stays `x` on every row (a bound that never binds).
    fn constant(x: i64) -> Self {
        Self {
            x,
            s: 0,
            d: 1,
            dq: 0,
            dr: 0,
        }
    }

    #[inline(always)]
    fn step(&mut self) {
        // n + dn = d·(x + dq) - (s - dr); the carry is irregular, so keep it branch-free.
        self.x += self.dq;
        self.s -= self.dr;
        let borrow = self.s >> 63; // -1 when s < 0, else 0
        self.s += self.d & borrow;
        self.x -= borrow;
    }
}

/// Calls `f(y, x_start, x_end)` (x_end inclusive) for every row of pixels the triangle `tri`
/// (pixel coordinates) covers inside a `width` x `height` target. Either winding is accepted.
/// Coordinates must be finite. Degenerate (zero-area) triangles cover nothing.
pub fn for_each_span(
    tri: [[f64; 2]; 3],
    width: usize,
    height: usize,
    f: &mut impl FnMut(usize, usize, usize),
) {
    let (w, h) = (width as f64, height as f64);
    let inside_guard =
        |p: &[f64; 2]| p[0] >= -GUARD && p[0] <= w + GUARD && p[1] >= -GUARD && p[1] <= h + GUARD;
    if tri.iter().all(inside_guard) {
        fill_snapped(tri, width, height, f);
        return;
    }
    let poly = clip_to_box(&tri, -GUARD, -GUARD, w + GUARD, h + GUARD);
    for k in 1..poly.len().saturating_sub(1) {
        fill_snapped([poly[0], poly[k], poly[k + 1]], width, height, f);
    }
}

fn fill_snapped(
    tri: [[f64; 2]; 3],
    width: usize,
    height: usize,
    f: &mut impl FnMut(usize, usize, usize),
) {
    let round = |v: f64| (v + 0.5f64.copysign(v)) as i64; // no libm call, unlike f64::round
    let snap = |p: [f64; 2]| (round(p[0] * SUB as f64), round(p[1] * SUB as f64));
    let (p0, mut p1, mut p2) = (snap(tri[0]), snap(tri[1]), snap(tri[2]));
    let area2 = (p1.0 - p0.0) * (p2.1 - p0.1) - (p1.1 - p0.1) * (p2.0 - p0.0);
    if area2 == 0 {
        return;
    }
    if area2 > 0 {
        std::mem::swap(&mut p1, &mut p2); // interior on the non-negative side of every edge
    }
    let edges = [Edge::new(p0, p1), Edge::new(p1, p2), Edge::new(p2, p0)];
    let (xmax_px, ymax_px) = (width as i64 - 1, height as i64 - 1);
    let ymin = p0.1.min(p1.1).min(p2.1);
    let ymax = p0.1.max(p1.1).max(p2.1);
    let xmin = p0.0.min(p1.0).min(p2.0);
    let xmax = p0.0.max(p1.0).max(p2.0);
    // Bounding box in pixel centres, clipped to the target.
    let mut row_first = (-((-ymin).div_euclid(SUB))).max(0);
    let mut row_last = ymax.div_euclid(SUB).min(ymax_px);
    let col_first = (-((-xmin).div_euclid(SUB))).max(0);
    let col_last = xmax.div_euclid(SUB).min(xmax_px);
    // A flat edge (a = 0) bounds the rows: b·py + c >= 0, with b != 0 as the area is not zero.
    for e in edges.iter().filter(|e| e.a == 0) {
        if e.b > 0 {
            row_first = row_first.max(-(e.c.div_euclid(e.b))); // py >= ceil(-c / b)
        } else {
            row_last = row_last.min(e.c.div_euclid(-e.b)); // py <= floor(c / -b)
        }
    }
    if row_first > row_last || col_first > col_last {
        return;
    }
    // The other edges bound each row: the first pixel (a > 0) or one past the last (a < 0),
    // stepped exactly from row to row. A triangle has at most two of each kind; a missing one
    // is a constant bound at the box's edge.
    let mut lower = [
        CeilStepper::constant(col_first),
        CeilStepper::constant(col_first),
    ];
    let mut upper = [
        CeilStepper::constant(col_last + 1),
        CeilStepper::constant(col_last + 1),
    ];
    let (mut nl, mut nu) = (0, 0);
    for e in &edges {
        let r = e.b * row_first + e.c; // E = a·px + r >= 0
        if e.a > 0 {
            lower[nl] = CeilStepper::new(-r, e.a, -e.b); // px >= ceil(-r / a)
            nl += 1;
        } else if e.a < 0 {
            upper[nu] = CeilStepper::new(r + 1, -e.a, e.b); // px < ceil((r + 1) / -a)
            nu += 1;
        }
    }
    // Four named steppers rather than an array, so that they stay in registers.
    let ([mut l0, mut l1], [mut u0, mut u1]) = (lower, upper);
    for py in row_first..=row_last {
        let lo = col_first.max(l0.x).max(l1.x);
        let hi = col_last.min(u0.x - 1).min(u1.x - 1);
        l0.step();
        l1.step();
        u0.step();
        u1.step();
        if lo <= hi {
            f(py as usize, lo as usize, hi as usize);
        }
    }
}

/// Sutherland-Hodgman clip of a triangle against an axis-aligned box; returns a convex polygon.
fn clip_to_box(tri: &[[f64; 2]; 3], x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    let mut poly: Vec<[f64; 2]> = tri.to_vec();
    // (axis, bound, keep when coordinate >= bound if true, <= if false)
    for (axis, bound, keep_ge) in [(0, x0, true), (0, x1, false), (1, y0, true), (1, y1, false)] {
        let inside = |p: &[f64; 2]| {
            if keep_ge {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        let mut out = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn count(tris: &[[[f64; 2]; 3]], w: usize, h: usize) -> Vec<u32> {
        let mut cov = vec![0u32; w * h];
        for t in tris {
            for_each_span(*t, w, h, &mut |y, x0, x1| {
                for x in x0..=x1 {
                    cov[y * w + x] += 1;
                }
            });
        }
        cov
    }

    #[test]
    fn axis_aligned_square_covers_its_pixels_once() {
        // Square with corners on pixel boundaries: covers pixels 2..=5 x 1..=3 exactly.
        let (a, b, c, d) = ([1.5, 0.5], [5.5, 0.5], [5.5, 3.5], [1.5, 3.5]);
        let cov = count(&[[a, b, c], [a, c, d]], 8, 6);
        for y in 0..6 {
            for x in 0..8 {
                let want = (2..=5).contains(&x) && (1..=3).contains(&y);
                assert_eq!(cov[y * 8 + x], want as u32, "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn degenerate_triangle_covers_nothing() {
        assert!(count(&[[[0.0, 0.0], [4.0, 4.0], [8.0, 8.0]]], 10, 10)
            .iter()
            .all(|&c| c == 0));
    }

    #[test]
    fn huge_triangle_is_clipped_and_fills_target() {
        let cov = count(&[[[-1e9, -1e9], [1e9, -1e9], [0.0, 1e9]]], 16, 16);
        assert!(cov.iter().all(|&c| c == 1));
    }

    #[test]
    fn fan_around_shared_vertex_covers_once() {
        // Eight triangles around a vertex exactly on a pixel centre.
        let c = [5.0, 5.0];
        let ring = [
            [1.0, 1.0],
            [5.0, 0.0],
            [9.0, 1.0],
            [10.0, 5.0],
            [9.0, 9.0],
            [5.0, 10.0],
            [1.0, 9.0],
            [0.0, 5.0],
        ];
        let tris: Vec<_> = (0..8).map(|i| [c, ring[i], ring[(i + 1) % 8]]).collect();
        let cov = count(&tris, 12, 12);
        assert_eq!(cov[5 * 12 + 5], 1);
        assert!(cov.iter().all(|&n| n <= 1));
    }

    proptest! {
        /// A quad split along either diagonal, with arbitrary sub-pixel vertices, covers every
        /// pixel at most once and exactly the pixels its two halves cover.
        #[test]
        fn shared_edge_never_double_covers(
            pts in proptest::collection::vec((-4.0f64..36.0, -4.0f64..36.0), 4),
        ) {
            let p: Vec<[f64; 2]> = pts.iter().map(|&(x, y)| [x, y]).collect();
            let cov = count(&[[p[0], p[1], p[2]], [p[0], p[2], p[3]]], 32, 32);
            prop_assert!(cov.iter().all(|&c| c <= 2));
            // Convex quads (both diagonals inside) must be covered at most once.
            let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            let s: Vec<f64> = (0..4).map(|i| cross(p[i], p[(i + 1) % 4], p[(i + 2) % 4])).collect();
            if s.iter().all(|&v| v > 1e-6) || s.iter().all(|&v| v < -1e-6) {
                prop_assert!(cov.iter().all(|&c| c <= 1));
            }
        }

        /// A regular grid of triangles covers every pixel centre inside the grid exactly once,
        /// whatever its sub-pixel offset and spacing.
        #[test]
        fn tiled_grid_covers_exactly_once(
            ox in -3.0f64..3.0, oy in -3.0f64..3.0, sx in 1.3f64..7.0, sy in 1.3f64..7.0, flip in any::<bool>(),
        ) {
            let (n, w, h) = (6, 48usize, 48usize);
            let v = |i: usize, j: usize| [ox + i as f64 * sx, oy + j as f64 * sy];
            let mut tris = vec![];
            for j in 0..n { for i in 0..n {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                if flip { tris.push([a, b, d]); tris.push([b, c, d]); }
                else { tris.push([a, b, c]); tris.push([a, c, d]); }
            }}
            let cov = count(&tris, w, h);
            let (x1, y1) = (ox + n as f64 * sx, oy + n as f64 * sy);
            for y in 0..h { for x in 0..w {
                let (fx, fy) = (x as f64, y as f64);
                let m = 1.0 / SUB as f64; // vertices move by up to half a snap step
                let strictly_in = fx > ox + m && fx < x1 - m && fy > oy + m && fy < y1 - m;
                let strictly_out = fx < ox - m || fx > x1 + m || fy < oy - m || fy > y1 + m;
                let c = cov[y * w + x];
                prop_assert!(c <= 1, "pixel ({}, {}) covered {} times", x, y, c);
                if strictly_in { prop_assert_eq!(c, 1, "hole at ({}, {})", x, y); }
                if strictly_out { prop_assert_eq!(c, 0); }
            }}
        }

        /// Spans never leave the target, whatever the triangle.
        #[test]
        fn spans_stay_inside_target(
            pts in proptest::collection::vec((-1e7f64..1e7, -1e7f64..1e7), 3),
            w in 1usize..40, h in 1usize..40,
        ) {
            let t = [[pts[0].0, pts[0].1], [pts[1].0, pts[1].1], [pts[2].0, pts[2].1]];
            for_each_span(t, w, h, &mut |y, x0, x1| {
                assert!(y < h && x0 <= x1 && x1 < w);
            });
        }
    }
}
