//! STB-snakes (Nesi & Magnolfi 1996, §2; docs/method.md §1): open curves given by m+1 knots, drawn as
//! the linear B-spline through them with n points per segment, moved frame to frame by the
//! paper's sign-descent solver.
//!
//! Several curves are solved jointly: they index one shared knot array (the mouth's upper and
//! lower curves share their corner knots), and *pairs* of knots couple curves (a minimum gap that
//! keeps lips from collapsing, a kept gap that holds the brow's thickness).
//!
//! Coordinates are image pixels (x right, y down, origin at the centre of the top-left pixel).

mod energy;
mod field;
mod frame;
mod frame_field;
mod plan;
mod rest;
mod solver;

pub use energy::{CurveParams, Operator, PairKind, PairSpec};
pub use field::{Field, FIELD_CHANNELS};
pub use frame::{
    band_regions, region, reported_knots, solve_frame, Band, FrameTimes, Knots, MorePasses,
};
pub use frame_field::{check_sigma, field_shape, frame_field, MAX_SIGMA};
pub use plan::{Assessed, Begun, FramePlan, Settled};
pub use solver::{FrameInput, Problem, Settings, Solution};
