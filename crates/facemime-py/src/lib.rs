//! `facemime._core`: the private native module. Converts numpy arrays to core views, releases
//! the GIL around the work and maps core errors once (see `error.rs`). One file per domain.

use pyo3::prelude::*;

mod adjust;
mod codec;
mod error;
mod flow;
mod head;
mod lip_search;
mod motion;
mod plan;
mod points;
mod pose;
mod raster;
mod snake;
mod template;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    adjust::register(m)?;
    codec::register(m)?;
    flow::register(m)?;
    head::register(m)?;
    lip_search::register(m)?;
    motion::register(m)?;
    plan::register(m)?;
    pose::register(m)?;
    raster::register(m)?;
    snake::register(m)?;
    template::register(m)?;
    Ok(())
}
