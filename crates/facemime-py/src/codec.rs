//! Bindings of `facemime_core::codec`: the bitstream's encoder and decoder. Python drives them
//! (`facemime.codec`); all packet, prediction, quantisation and entropy coding happens here.

use facemime_core::codec::{self, chunk, Header, Output, Quantiser};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::error::{invalid, CoreErr};

fn fixed<const N: usize>(name: &str, bytes: &[u8]) -> PyResult<[u8; N]> {
    bytes
        .try_into()
        .map_err(|_| invalid(format!("{name} must be {N} bytes")))
}

/// A pushed frame's reconstruction and the packet it completed.
type Pushed<'py> = (Bound<'py, PyArray1<f64>>, Option<Bound<'py, PyBytes>>);

/// The stream encoder. `steps`, `references`, `classes`: per parameter (the six pose
/// parameters, then the coefficients, then the extras); `basis`: (M, rows) basis vectors,
/// entries ×32767; `hysteresis`: steps of hysteresis of the quantiser; `extras`: the kinds of
/// the last parameters (empty: a version-1 stream; `docs/bitstream.md`, "Look").
#[pyclass(module = "facemime._core")]
pub struct StreamEncoder {
    enc: codec::Encoder,
}

#[pymethods]
impl StreamEncoder {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (fps, size, topology, packet_frames, keyframe_packets, steps, references, classes, basis, actor_id,
                        actor_in_stream, hysteresis, extras=Vec::new()))]
    fn new(
        fps: (u32, u32),
        size: (u16, u16),
        topology: &[u8],
        packet_frames: u8,
        keyframe_packets: u16,
        steps: Vec<f32>,
        references: Vec<i32>,
        classes: Vec<u8>,
        basis: PyReadonlyArray2<i16>,
        actor_id: &[u8],
        actor_in_stream: bool,
        hysteresis: f64,
        extras: Vec<u8>,
    ) -> PyResult<Self> {
        if steps.len() != references.len() || steps.len() != classes.len() {
            return Err(invalid(
                "steps, references and classes must have one entry per parameter",
            ));
        }
        let b = basis.as_array();
        let header = Header {
            fps_num: fps.0,
            fps_den: fps.1,
            width: size.0,
            height: size.1,
            topology: fixed("topology", topology)?,
            packet_frames,
            keyframe_packets,
            quantisers: steps
                .iter()
                .zip(&references)
                .zip(&classes)
                .map(|((&step, &reference), &class)| Quantiser {
                    step,
                    reference,
                    class,
                })
                .collect(),
            extras,
            basis_rows: u16::try_from(b.ncols())
                .map_err(|_| invalid("basis vectors are too long"))?,
            basis: b.iter().copied().collect(),
            actor_id: fixed("actor_id", actor_id)?,
            actor_in_stream,
        };
        Ok(StreamEncoder {
            enc: codec::Encoder::new(header, hysteresis).map_err(CoreErr)?,
        })
    }

    /// The header chunk (the stream's first bytes).
    fn header_chunk<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.enc.header_chunk())
    }

    /// Adds a frame; returns (what the decoder will output for it, (N,) float64; the packet this
    /// frame completed, or None).
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        face: bool,
        lost: u8,
        values: PyReadonlyArray1<f64>,
    ) -> PyResult<Pushed<'py>> {
        let v = values
            .as_slice()
            .map_err(|_| invalid("values must be contiguous"))?;
        let (recon, packet) = self.enc.push(face, lost, v).map_err(CoreErr)?;
        Ok((recon.into_pyarray(py), packet.map(|p| PyBytes::new(py, &p))))
    }

    /// The last packet, if frames are pending.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyBytes>>> {
        Ok(self
            .enc
            .finish()
            .map_err(CoreErr)?
            .map(|p| PyBytes::new(py, &p)))
    }

    /// Whether the next packet will be an intra packet.
    fn next_is_intra(&self) -> bool {
        self.enc.next_is_intra()
    }

    /// Makes the next packet an intra packet, whatever its number.
    fn request_intra(&mut self) {
        self.enc.request_intra()
    }
}

/// The actor chunk carrying `payload`.
#[pyfunction]
fn actor_chunk<'py>(py: Python<'py>, payload: &[u8]) -> PyResult<Bound<'py, PyBytes>> {
    if payload.len() > chunk::Kind::Actor.max_payload() {
        return Err(invalid(
            "the actor is larger than a stream may carry (64 MiB)",
        ));
    }
    Ok(PyBytes::new(
        py,
        &chunk::write(chunk::Kind::Actor, 0, 0, payload),
    ))
}

/// The appearance chunk carrying `payload` (`u32` first frame, `u16` x, `u16` y, then a WebP
/// image; `docs/bitstream.md`, "Appearance"), 8 bytes to 1 MiB.
#[pyfunction]
fn appearance_chunk<'py>(py: Python<'py>, payload: &[u8]) -> PyResult<Bound<'py, PyBytes>> {
    Ok(PyBytes::new(
        py,
        &chunk::appearance(payload).map_err(CoreErr)?,
    ))
}

/// Spread class per parameter for a clip (see `facemime_core::codec::choose_classes`):
/// `values` (T, N), the frames that show a face.
#[pyfunction]
fn choose_classes(
    steps: Vec<f64>,
    hysteresis: f64,
    values: PyReadonlyArray2<f64>,
) -> PyResult<Vec<u8>> {
    let v = values.as_array();
    let frames: Vec<Vec<f64>> = v.rows().into_iter().map(|r| r.to_vec()).collect();
    Ok(codec::choose_classes(&steps, hysteresis, &frames).map_err(CoreErr)?)
}

/// Decoded frames: (index (F,) uint64, face (F,) bool, lost (F,) uint8, values (F, N) float64,
/// concealed (C, 2) uint64 of (first frame, count), appearance: the appearance payloads in
/// stream order, each as (frames output before it in this call, decoded and concealed, payload)).
type Decoded<'py> = (
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u64>>,
    Vec<(u64, Bound<'py, PyBytes>)>,
);

/// The stream decoder, fed bytes in pieces of any size. `from_start`: the stream starts at
/// packet 0 (a file); false for a receiver that joins a live stream.
#[pyclass(module = "facemime._core")]
pub struct StreamDecoder {
    dec: codec::Decoder,
}

impl StreamDecoder {
    fn arrays<'py>(&self, py: Python<'py>, out: Vec<Output>) -> Decoded<'py> {
        let n = self.dec.header().map_or(0, |h| h.quantisers.len());
        let (mut index, mut face, mut lost, mut values, mut concealed, mut appearance) =
            (vec![], vec![], vec![], vec![], vec![], vec![]);
        let mut seen = 0; // frames output so far, decoded and concealed
        for o in out {
            match o {
                Output::Frame {
                    index: i,
                    face: f,
                    lost: l,
                    values: v,
                } if v.len() == n => {
                    index.push(i);
                    face.push(f);
                    lost.push(l);
                    values.extend(v);
                    seen += 1;
                }
                Output::Frame { .. } => {}
                Output::Concealed { first, count } => {
                    concealed.extend([first, count]);
                    seen += count;
                }
                Output::Appearance(p) => appearance.push((seen, PyBytes::new(py, &p))),
            }
        }
        let rows = index.len();
        (
            index.into_pyarray(py),
            face.into_pyarray(py),
            lost.into_pyarray(py),
            ndarray::Array2::from_shape_vec((rows, n), values)
                .expect("F x N")
                .into_pyarray(py),
            ndarray::Array2::from_shape_vec((concealed.len() / 2, 2), concealed)
                .expect("C x 2")
                .into_pyarray(py),
            appearance,
        )
    }
}

#[pymethods]
impl StreamDecoder {
    #[new]
    fn new(from_start: bool) -> Self {
        StreamDecoder {
            dec: codec::Decoder::new(from_start),
        }
    }

    /// Reads `data`; returns the frames it completed and the appearance payloads it held, up to
    /// a header that starts a new stream (then `pending()` is true: call again with no bytes),
    /// so that everything returned belongs to the header `header()` gives.
    fn push<'py>(&mut self, py: Python<'py>, data: &[u8]) -> Decoded<'py> {
        let out = py.detach(|| self.dec.segment(data, false));
        self.arrays(py, out)
    }

    /// Reads what is buffered as the stream's end (up to a new header, as `push`).
    fn finish<'py>(&mut self, py: Python<'py>) -> Decoded<'py> {
        let out = self.dec.segment(&[], true);
        self.arrays(py, out)
    }

    /// Whether the last `push` or `finish` stopped before a new header.
    fn pending(&self) -> bool {
        self.dec.pending()
    }

    /// The header as a dict (None before one was read): fps (num, den), size (w, h), topology,
    /// packet_frames, keyframe_packets, steps, references, classes (per parameter), extras (the
    /// kinds of the last parameters, empty for version 1), basis (M, rows) int16, actor_id,
    /// actor_in_stream.
    fn header<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(h) = self.dec.header() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("fps", (h.fps_num, h.fps_den))?;
        d.set_item("size", (h.width, h.height))?;
        d.set_item("topology", PyBytes::new(py, &h.topology))?;
        d.set_item("packet_frames", h.packet_frames)?;
        d.set_item("keyframe_packets", h.keyframe_packets)?;
        d.set_item(
            "steps",
            h.quantisers.iter().map(|q| q.step).collect::<Vec<_>>(),
        )?;
        d.set_item(
            "references",
            h.quantisers.iter().map(|q| q.reference).collect::<Vec<_>>(),
        )?;
        d.set_item(
            "classes",
            h.quantisers.iter().map(|q| q.class).collect::<Vec<_>>(),
        )?;
        // a list of ints (a Vec<u8> would become bytes)
        d.set_item(
            "extras",
            h.extras.iter().map(|&k| k as u32).collect::<Vec<_>>(),
        )?;
        let basis = ndarray::Array2::from_shape_vec(
            (h.coefficients(), h.basis_rows as usize),
            h.basis.clone(),
        )
        .expect("M x rows");
        d.set_item("basis", basis.into_pyarray(py))?;
        d.set_item("actor_id", PyBytes::new(py, &h.actor_id))?;
        d.set_item("actor_in_stream", h.actor_in_stream)?;
        Ok(Some(d))
    }

    /// Why a well-framed header was refused, if one was.
    fn header_error(&self) -> Option<String> {
        self.dec.header_error().map(str::to_owned)
    }

    /// The actor chunk's payload, once read.
    fn actor<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyBytes>> {
        self.dec.actor().map(|a| PyBytes::new(py, a))
    }

    /// What the decoder met (see `facemime_core::codec::Stats`).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.dec.stats;
        let d = PyDict::new(py);
        for (k, v) in [
            ("packets", s.packets),
            ("lost_packets", s.lost_packets),
            ("late_packets", s.late_packets),
            ("undecodable", s.undecodable),
            ("appearance", s.appearance),
            ("damaged_runs", s.damaged_runs),
            ("damaged_bytes", s.damaged_bytes),
            ("frames", s.frames),
            ("concealed", s.concealed),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<StreamEncoder>()?;
    m.add_class::<StreamDecoder>()?;
    m.add_function(wrap_pyfunction!(actor_chunk, m)?)?;
    m.add_function(wrap_pyfunction!(appearance_chunk, m)?)?;
    m.add_function(wrap_pyfunction!(choose_classes, m)?)?;
    Ok(())
}
