//! Textured triangle meshes: culling, visibility order, per-triangle affine texture mapping.

use ndarray::{Array2, ArrayView1, ArrayView2};

use super::image::{check_size, ImageMut, ImageRef};
use super::sampler::{Bilinear, Nearest, Sampler, SpanStart, ONE};
use super::span::for_each_span;
use crate::error::Result;
use crate::invalid;

/// Texture filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Nearest,
    Bilinear,
}

/// How nearer triangles hide farther ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthMode {
    /// Draw whole triangles far to near by mean vertex depth (the paper's method).
    Painter,
    /// Per-pixel depth test against a z-buffer (exact for interpenetrating triangles).
    ZBuffer,
}

/// Options of [`render_mesh_into`].
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    pub filter: Filter,
    pub depth: DepthMode,
    /// Skip triangles that face away from the camera (see [`render_mesh_into`] for the winding).
    pub cull_back_faces: bool,
}

/// What a render did, for callers and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Triangles rasterised (after culling and degenerate-skipping).
    pub drawn: usize,
    /// Triangles skipped as back-facing.
    pub culled: usize,
    /// Triangles skipped because their image triangle has zero area.
    pub degenerate: usize,
    /// Pixel writes (a pixel drawn twice counts twice).
    pub pixels: usize,
}

/// Largest |coordinate| accepted for image and texture points (pixels).
const MAX_COORD: f64 = 1e9;

/// The per-triangle affine maps of eq. 18: texture position and depth as functions of the
/// image position, `P = A + M (P' - A')`.
struct TriangleMap {
    origin: [f64; 2], // A' (image)
    src: [f64; 2],    // A (texture)
    m: [[f64; 2]; 2], // M, row-major: src = src0 + M · (dst - origin)
    depth: f64,       // depth at A'
    depth_grad: [f64; 2],
}

impl TriangleMap {
    /// `None` when the image triangle has zero area.
    fn new(dst: [[f64; 2]; 3], src: [[f64; 2]; 3], z: [f64; 3]) -> Option<Self> {
        let (db, dc) = (sub(dst[1], dst[0]), sub(dst[2], dst[0]));
        let det = db[0] * dc[1] - db[1] * dc[0];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        // D = [db dc] (columns); D^-1 = [[dc.y, -dc.x], [-db.y, db.x]] / det.
        let inv = [[dc[1] / det, -dc[0] / det], [-db[1] / det, db[0] / det]];
        let (sb, sc) = (sub(src[1], src[0]), sub(src[2], src[0]));
        let m = [
            [
                sb[0] * inv[0][0] + sc[0] * inv[1][0],
                sb[0] * inv[0][1] + sc[0] * inv[1][1],
            ],
            [
                sb[1] * inv[0][0] + sc[1] * inv[1][0],
                sb[1] * inv[0][1] + sc[1] * inv[1][1],
            ],
        ];
        let (zb, zc) = (z[1] - z[0], z[2] - z[0]);
        let depth_grad = [
            zb * inv[0][0] + zc * inv[1][0],
            zb * inv[0][1] + zc * inv[1][1],
        ];
        Some(Self {
            origin: dst[0],
            src: src[0],
            m,
            depth: z[0],
            depth_grad,
        })
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn signed_area2(t: &[[f64; 2]; 3]) -> f64 {
    (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0])
}

fn check_points(name: &str, p: &ArrayView2<f64>, n: usize) -> Result<()> {
    if p.ncols() != 2 || p.nrows() != n {
        return invalid!(
            "{name} must have shape ({n}, 2), got ({}, {})",
            p.nrows(),
            p.ncols()
        );
    }
    if let Some(v) = p.iter().find(|v| !(v.is_finite() && v.abs() <= MAX_COORD)) {
        return invalid!("{name} must be finite and within ±{MAX_COORD:e} pixels, found {v}");
    }
    Ok(())
}

fn check_triangles(triangles: &ArrayView2<u32>, n: usize) -> Result<()> {
    if triangles.ncols() != 3 {
        return invalid!(
            "triangles must have shape (F, 3), got (F, {})",
            triangles.ncols()
        );
    }
    if let Some(&i) = triangles.iter().find(|&&i| i as usize >= n) {
        return invalid!("triangles index vertex {i}, but there are only {n} vertices");
    }
    Ok(())
}

/// Renders a textured triangle mesh into `out` (pixels outside every triangle are untouched).
///
/// - `tex_points`: (N, 2) texture position of each vertex, texel pixels (x, y), texel centres
///   on integers; lookups beyond the texture clamp to its edge.
/// - `points`: (N, 2) image position of each vertex, pixels (x, y), y down.
/// - `depth`: (N,) depth of each vertex, larger = nearer the camera (any unit).
/// - `triangles`: (F, 3) vertex indices. A triangle faces the camera when its vertices run
///   counter-clockwise *as seen* on the image (a model's outward winding survives the y flip of
///   the projection); in y-down pixel coordinates that is a negative cross product
///   (B - A) x (C - A). With `cull_back_faces` the others are skipped, otherwise both sides
///   are drawn.
///
/// Every destination pixel P' of a triangle takes the texture at `P = A + M (P' - A')`
/// (eq. 18), so deformed triangles never leave holes.
pub fn render_mesh_into(
    out: &mut ImageMut,
    texture: &ImageRef,
    tex_points: ArrayView2<f64>,
    points: ArrayView2<f64>,
    depth: ArrayView1<f64>,
    triangles: ArrayView2<u32>,
    opts: RenderOptions,
) -> Result<RenderStats> {
    let n = points.nrows();
    check_points("points", &points, n)?;
    check_points("tex_points", &tex_points, n)?;
    if depth.len() != n {
        return invalid!("depth must have shape ({n},), got ({},)", depth.len());
    }
    if let Some(z) = depth.iter().find(|z| !z.is_finite()) {
        return invalid!("depth must be finite, found {z}");
    }
    check_triangles(&triangles, n)?;
    if texture.channels != out.channels {
        return invalid!(
            "texture has {} channels but the output image has {}",
            texture.channels,
            out.channels
        );
    }
    match (out.channels, opts.filter) {
        (1, Filter::Nearest) => {
            draw::<Nearest, 1>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (2, Filter::Nearest) => {
            draw::<Nearest, 2>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (3, Filter::Nearest) => {
            draw::<Nearest, 3>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (4, Filter::Nearest) => {
            draw::<Nearest, 4>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (1, Filter::Bilinear) => {
            draw::<Bilinear, 1>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (2, Filter::Bilinear) => {
            draw::<Bilinear, 2>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (3, Filter::Bilinear) => {
            draw::<Bilinear, 3>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (4, Filter::Bilinear) => {
            draw::<Bilinear, 4>(out, texture, &tex_points, &points, &depth, &triangles, opts)
        }
        (c, _) => invalid!("images must have 1 to 4 channels, got {c}"),
    }
}

fn corner(p: &ArrayView2<f64>, i: u32) -> [f64; 2] {
    [p[[i as usize, 0]], p[[i as usize, 1]]]
}

fn draw<S: Sampler, const C: usize>(
    out: &mut ImageMut,
    texture: &ImageRef,
    tex_points: &ArrayView2<f64>,
    points: &ArrayView2<f64>,
    depth: &ArrayView1<f64>,
    triangles: &ArrayView2<u32>,
    opts: RenderOptions,
) -> Result<RenderStats> {
    let mut stats = RenderStats::default();
    // Visible triangles with their mean depth, then far to near for the painter's order.
    let mut order: Vec<(f64, usize)> = Vec::with_capacity(triangles.nrows());
    for (f, tri) in triangles.outer_iter().enumerate() {
        let dst = [
            corner(points, tri[0]),
            corner(points, tri[1]),
            corner(points, tri[2]),
        ];
        let area2 = signed_area2(&dst);
        if area2 == 0.0 {
            stats.degenerate += 1;
        } else if opts.cull_back_faces && area2 > 0.0 {
            stats.culled += 1;
        } else {
            order.push((
                (depth[tri[0] as usize] + depth[tri[1] as usize] + depth[tri[2] as usize]) / 3.0,
                f,
            ));
        }
    }
    if opts.depth == DepthMode::Painter {
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let mut zbuf = match opts.depth {
        DepthMode::ZBuffer => vec![f32::NEG_INFINITY; out.width * out.height],
        DepthMode::Painter => Vec::new(),
    };
    let width = out.width;
    let mut batch: Vec<SpanStart> = Vec::new();
    for &(_, f) in &order {
        let tri = triangles.row(f);
        let dst = [
            corner(points, tri[0]),
            corner(points, tri[1]),
            corner(points, tri[2]),
        ];
        let src = [
            corner(tex_points, tri[0]),
            corner(tex_points, tri[1]),
            corner(tex_points, tri[2]),
        ];
        let z = [
            depth[tri[0] as usize],
            depth[tri[1] as usize],
            depth[tri[2] as usize],
        ];
        let Some(map) = TriangleMap::new(dst, src, z) else {
            stats.degenerate += 1;
            continue;
        };
        stats.drawn += 1;
        // Round half away from zero with a cast: f64::round is a libm call on baseline x86-64.
        let to_fixed = |v: f64| (v * ONE as f64 + 0.5f64.copysign(v)) as i64;
        let (du, dv) = (to_fixed(map.m[0][0]), to_fixed(map.m[1][0]));
        let data = &mut *out.data;
        let zbuf = &mut zbuf;
        let batch = &mut batch;
        batch.clear();
        let mut pixels = 0usize;
        for_each_span(dst, out.width, out.height, &mut |y, x0, x1| {
            // Texture position and depth at the span's first pixel centre, then per-pixel steps.
            let (rx, ry) = (x0 as f64 - map.origin[0], y as f64 - map.origin[1]);
            let mut u = to_fixed(map.src[0] + map.m[0][0] * rx + map.m[0][1] * ry);
            let mut v = to_fixed(map.src[1] + map.m[1][0] * rx + map.m[1][1] * ry);
            let row = y * width;
            let span = &mut data[(row + x0) * C..(row + x1 + 1) * C];
            if zbuf.is_empty() {
                let last = (x1 - x0) as i64;
                if S::in_bounds(texture, u, v)
                    && S::in_bounds(texture, u + du * last, v + dv * last)
                {
                    // The footprint is affine along the span: both ends inside means all
                    // inside. Drawn with the triangle's other such spans below.
                    batch.push(SpanStart {
                        at: (row + x0) * C,
                        len: x1 - x0 + 1,
                        u,
                        v,
                    });
                } else {
                    for px in span.chunks_exact_mut(C) {
                        px.copy_from_slice(&S::sample::<C>(texture, u, v));
                        u += du;
                        v += dv;
                    }
                }
                pixels += x1 - x0 + 1;
            } else {
                let mut zd = map.depth + map.depth_grad[0] * rx + map.depth_grad[1] * ry;
                let zrow = &mut zbuf[row + x0..=row + x1];
                for (px, zb) in span.chunks_exact_mut(C).zip(zrow.iter_mut()) {
                    if zd as f32 > *zb {
                        *zb = zd as f32;
                        px.copy_from_slice(&S::sample::<C>(texture, u, v));
                        pixels += 1;
                    }
                    u += du;
                    v += dv;
                    zd += map.depth_grad[0];
                }
            }
        });
        // SAFETY: in_bounds holds at both ends of every batched span, hence at every pixel
        // between, and for_each_span keeps spans inside the image.
        unsafe { S::fill_spans_unchecked::<C>(texture, du, dv, batch, data) };
        stats.pixels += pixels;
    }
    Ok(stats)
}

/// How many triangles cover each pixel of a `width` x `height` image: a (height, width) array.
/// Both windings count. Useful to find holes (0 inside a face) and overlaps (> 1).
pub fn coverage(
    points: ArrayView2<f64>,
    triangles: ArrayView2<u32>,
    width: usize,
    height: usize,
) -> Result<Array2<u32>> {
    let n = points.nrows();
    check_points("points", &points, n)?;
    check_triangles(&triangles, n)?;
    check_size("coverage image", width, height)?;
    let mut cov = Array2::<u32>::zeros((height, width));
    for tri in triangles.outer_iter() {
        let dst = [
            corner(&points, tri[0]),
            corner(&points, tri[1]),
            corner(&points, tri[2]),
        ];
        for_each_span(dst, width, height, &mut |y, x0, x1| {
            cov.row_mut(y)
                .slice_mut(ndarray::s![x0..=x1])
                .mapv_inplace(|c| c + 1);
        });
    }
    Ok(cov)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{arr1, arr2, Array3};

    fn opts(filter: Filter, depth: DepthMode) -> RenderOptions {
        RenderOptions {
            filter,
            depth,
            cull_back_faces: true,
        }
    }

    fn gradient_texture(w: usize, h: usize) -> Array3<u8> {
        Array3::from_shape_fn((h, w, 3), |(y, x, c)| {
            ((x * 7 + y * 13 + c * 50) % 256) as u8
        })
    }

    #[test]
    fn translated_triangle_reproduces_texture_exactly_nearest() {
        let tex = gradient_texture(32, 32);
        let texr = ImageRef::new(tex.as_slice().unwrap(), 32, 32, 3).unwrap();
        let src = arr2(&[[2.0, 2.0], [28.0, 2.0], [2.0, 28.0]]);
        let dst = src.mapv(|v| v + 5.0);
        let mut out = vec![0u8; 48 * 48 * 3];
        let mut img = ImageMut::new(&mut out, 48, 48, 3).unwrap();
        // Counter-clockwise as seen = front-facing: (2,2) -> (2,28) -> (28,2) on the image.
        let tris = arr2(&[[0u32, 2, 1]]);
        let s = render_mesh_into(
            &mut img,
            &texr,
            src.view(),
            dst.view(),
            arr1(&[0.0; 3]).view(),
            tris.view(),
            opts(Filter::Nearest, DepthMode::Painter),
        )
        .unwrap();
        assert_eq!(s.drawn, 1);
        for y in 0..48 {
            for x in 0..48 {
                let (sx, sy) = (x as i64 - 5, y as i64 - 5);
                let inside = sx > 2 && sy > 2 && sx + sy < 30;
                if inside {
                    for c in 0..3 {
                        assert_eq!(
                            out[(y * 48 + x) * 3 + c],
                            tex[[sy as usize, sx as usize, c]]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn back_faces_are_culled() {
        let tex = gradient_texture(8, 8);
        let texr = ImageRef::new(tex.as_slice().unwrap(), 8, 8, 3).unwrap();
        let p = arr2(&[[0.0, 0.0], [7.0, 0.0], [0.0, 7.0]]);
        let mut out = vec![0u8; 8 * 8 * 3];
        let mut img = ImageMut::new(&mut out, 8, 8, 3).unwrap();
        // (0,0) -> (7,0) -> (0,7) runs clockwise as seen on the image: a back face.
        let s = render_mesh_into(
            &mut img,
            &texr,
            p.view(),
            p.view(),
            arr1(&[0.0; 3]).view(),
            arr2(&[[0u32, 1, 2]]).view(),
            opts(Filter::Bilinear, DepthMode::Painter),
        )
        .unwrap();
        assert_eq!((s.drawn, s.culled, s.pixels), (0, 1, 0));
        assert!(out.iter().all(|&v| v == 0));
    }

    #[test]
    fn nearer_triangle_hides_farther_in_both_modes() {
        // Texture: left half 10, right half 200; far triangle samples the left, near the right.
        let tex = Array3::from_shape_fn((4, 4, 1), |(_, x, _)| if x < 2 { 10u8 } else { 200 });
        let texr = ImageRef::new(tex.as_slice().unwrap(), 4, 4, 1).unwrap();
        let pts = arr2(&[
            [0.0, 0.0],
            [0.0, 19.0],
            [19.0, 0.0],
            [0.0, 0.0],
            [0.0, 19.0],
            [19.0, 0.0],
        ]);
        let tp = arr2(&[
            [0.0, 0.0],
            [0.0, 0.0],
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 0.0],
            [3.0, 0.0],
        ]);
        let tp = tp
            + arr2(&[
                [0.0, 0.0],
                [0.0, 1.0],
                [1.0, 0.0],
                [0.0, 0.0],
                [0.0, 1.0],
                [-0.01, 0.0],
            ]) * 0.001;
        let z = arr1(&[1.0, 1.0, 1.0, 2.0, 2.0, 2.0]);
        for mode in [DepthMode::Painter, DepthMode::ZBuffer] {
            // Near triangle listed first so that draw order alone would be wrong.
            let tris = arr2(&[[3u32, 4, 5], [0, 1, 2]]);
            let mut out = vec![0u8; 20 * 20];
            let mut img = ImageMut::new(&mut out, 20, 20, 1).unwrap();
            render_mesh_into(
                &mut img,
                &texr,
                tp.view(),
                pts.view(),
                z.view(),
                tris.view(),
                opts(Filter::Nearest, mode),
            )
            .unwrap();
            assert_eq!(out[5 * 20 + 5], 200, "{mode:?}");
        }
    }

    #[test]
    fn bad_index_is_an_error_not_a_panic() {
        let tex = vec![0u8; 3];
        let texr = ImageRef::new(&tex, 1, 1, 3).unwrap();
        let p = arr2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let mut out = vec![0u8; 3];
        let mut img = ImageMut::new(&mut out, 1, 1, 3).unwrap();
        let err = render_mesh_into(
            &mut img,
            &texr,
            p.view(),
            p.view(),
            arr1(&[0.0; 3]).view(),
            arr2(&[[0u32, 1, 7]]).view(),
            opts(Filter::Nearest, DepthMode::Painter),
        )
        .unwrap_err();
        assert!(err.to_string().contains("vertex 7"));
        let nan = arr2(&[[f64::NAN, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!(render_mesh_into(
            &mut img,
            &texr,
            p.view(),
            nan.view(),
            arr1(&[0.0; 3]).view(),
            arr2(&[[0u32, 1, 2]]).view(),
            opts(Filter::Nearest, DepthMode::Painter)
        )
        .is_err());
    }

    #[test]
    fn oversized_image_is_refused() {
        assert!(ImageRef::new(&[], 100_000, 100_000, 3).is_err());
    }
}
