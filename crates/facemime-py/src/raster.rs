//! Bindings of `facemime_core::raster`.

use facemime_core::raster::{self, Border, DepthMode, Filter, ImageMut, ImageRef, RenderOptions};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
    PyReadwriteArray3,
};
use pyo3::prelude::*;

use crate::error::{invalid, CoreErr};

/// A string argument as an error message shows it: quoted, at most 40 characters of it.
fn shown(s: &str) -> String {
    let head: String = s.chars().take(40).collect();
    if head.len() < s.len() {
        format!("{head:?}...")
    } else {
        format!("{s:?}")
    }
}

fn contiguous<'a>(name: &str, s: Option<&'a [u8]>) -> PyResult<&'a [u8]> {
    s.ok_or_else(|| invalid(format!("{name} must be a C-contiguous uint8 array")))
}

/// Renders a textured mesh into `out` (H, W, C) uint8 in place; returns
/// (drawn, culled, degenerate, pixels). See `facemime.render` for the documented API.
#[pyfunction]
#[pyo3(signature = (out, texture, tex_points, points, depth, triangles, filter, depth_mode, cull_back_faces))]
#[allow(clippy::too_many_arguments)]
fn render_mesh_into(
    py: Python<'_>,
    mut out: PyReadwriteArray3<u8>,
    texture: PyReadonlyArray3<u8>,
    tex_points: PyReadonlyArray2<f64>,
    points: PyReadonlyArray2<f64>,
    depth: PyReadonlyArray1<f64>,
    triangles: PyReadonlyArray2<u32>,
    filter: &str,
    depth_mode: &str,
    cull_back_faces: bool,
) -> PyResult<(usize, usize, usize, usize)> {
    let filter = match filter {
        "nearest" => Filter::Nearest,
        "bilinear" => Filter::Bilinear,
        other => {
            return Err(invalid(format!(
                "filter must be 'nearest' or 'bilinear', got {}",
                shown(other)
            )))
        }
    };
    let depth_mode = match depth_mode {
        "painter" => DepthMode::Painter,
        "zbuffer" => DepthMode::ZBuffer,
        other => {
            return Err(invalid(format!(
                "depth must be 'painter' or 'zbuffer', got {}",
                shown(other)
            )))
        }
    };
    let opts = RenderOptions {
        filter,
        depth: depth_mode,
        cull_back_faces,
    };
    let tshape = texture.as_array().shape().to_vec();
    let oshape = out.as_array().shape().to_vec();
    let tex_data = contiguous("texture", texture.as_slice().ok())?;
    let out_data = out
        .as_slice_mut()
        .map_err(|_| invalid("out must be a C-contiguous, writeable uint8 array"))?;
    let (tp, p, z, t) = (
        tex_points.as_array(),
        points.as_array(),
        depth.as_array(),
        triangles.as_array(),
    );
    let stats = py.detach(|| -> Result<_, CoreErr> {
        let tex = ImageRef::new(tex_data, tshape[1], tshape[0], tshape[2])?;
        let mut img = ImageMut::new(out_data, oshape[1], oshape[0], oshape[2])?;
        Ok(raster::render_mesh_into(&mut img, &tex, tp, p, z, t, opts)?)
    })?;
    Ok((stats.drawn, stats.culled, stats.degenerate, stats.pixels))
}

/// (height, width) uint32 count of the triangles covering each pixel.
#[pyfunction]
fn coverage<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<f64>,
    triangles: PyReadonlyArray2<u32>,
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyArray2<u32>>> {
    let (p, t) = (points.as_array(), triangles.as_array());
    let cov = py
        .detach(|| raster::coverage(p, t, width, height))
        .map_err(CoreErr)?;
    Ok(cov.into_pyarray(py))
}

/// (height, width, C) uint8: `image` (H, W, C) sampled bilinearly through the affine map `m`
/// (2, 3) from output pixels to image pixels; `border` "replicate" or "zero". See
/// `facemime.render.bilinear.sample_affine`.
#[pyfunction]
fn sample_affine<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<u8>,
    m: PyReadonlyArray2<f64>,
    width: usize,
    height: usize,
    border: &str,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let border = match border {
        "replicate" => Border::Replicate,
        "zero" => Border::Zero,
        other => {
            return Err(invalid(format!(
                "border must be 'replicate' or 'zero', got {}",
                shown(other)
            )))
        }
    };
    let m = m.as_array();
    if m.shape() != [2, 3] {
        return Err(invalid(format!(
            "the affine map must be 2x3, got {:?}",
            m.shape()
        )));
    }
    let map = [
        [m[[0, 0]], m[[0, 1]], m[[0, 2]]],
        [m[[1, 0]], m[[1, 1]], m[[1, 2]]],
    ];
    let shape = image.as_array().shape().to_vec();
    let data = contiguous("image", image.as_slice().ok())?;
    let channels = shape[2];
    let out = py.detach(|| -> Result<_, CoreErr> {
        let img = ImageRef::named("image", data, shape[1], shape[0], channels)?;
        raster::image::check_size("the sampled picture", width, height)?;
        let mut buf = vec![0u8; width * height * channels];
        let mut out = ImageMut::new(&mut buf, width, height, channels)?;
        raster::sample_affine(&img, map, &mut out, border)?;
        Ok(buf)
    })?;
    let array = numpy::ndarray::Array3::from_shape_vec((height, width, channels), out)
        .map_err(|e| invalid(e.to_string()))?;
    Ok(array.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(render_mesh_into, m)?)?;
    m.add_function(wrap_pyfunction!(sample_affine, m)?)?;
    m.add_function(wrap_pyfunction!(coverage, m)?)?;
    m.add("MAX_IMAGE_SIDE", raster::MAX_IMAGE_SIDE)?;
    m.add("MAX_IMAGE_PIXELS", raster::MAX_IMAGE_PIXELS)?;
    Ok(())
}
