"""Type stubs of the private native module ``facemime._core`` (checked by tests/test_core_stubs.py)."""

import numpy as np
import numpy.typing as npt

__version__: str
MAX_IMAGE_SIDE: int
MAX_IMAGE_PIXELS: int

def render_mesh_into(
    out: npt.NDArray[np.uint8],
    texture: npt.NDArray[np.uint8],
    tex_points: npt.NDArray[np.float64],
    points: npt.NDArray[np.float64],
    depth: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.uint32],
    filter: str,
    depth_mode: str,
    cull_back_faces: bool,
) -> tuple[int, int, int, int]: ...
def sample_affine(
    image: npt.NDArray[np.uint8],
    m: npt.NDArray[np.float64],
    width: int,
    height: int,
    border: str,
) -> npt.NDArray[np.uint8]: ...
def coverage(
    points: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.uint32],
    width: int,
    height: int,
) -> npt.NDArray[np.uint32]: ...
def elastic_adjust(
    points: npt.NDArray[np.float64],
    chains: npt.NDArray[np.uint32],
    chain_lengths: npt.NDArray[np.uint32],
    targets: npt.NDArray[np.float64],
    target_lengths: npt.NDArray[np.uint32],
    psi: float,
    shrink: float,
    epsilon: float,
    iterations: int,
    tolerance: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

class FlowFrames:
    """The pyramids of the last two frames and the Lucas-Kanade flow between them (see
    facemime.track.flow)."""

    def __init__(self, max_level: int, window: int) -> None: ...
    def push(self, frame: npt.NDArray[np.uint8], crop: tuple[int, int, int, int]) -> None: ...
    def track(
        self,
        points: npt.NDArray[np.float64],
        backward: bool,
        iterations: int,
        epsilon: float,
        min_eigen: float,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...

class HeadFollower:
    """The head's rigid points followed from frame to frame (see facemime.track.motion)."""

    def __init__(
        self,
        frame: npt.NDArray[np.uint8],
        brows: npt.NDArray[np.float64],
        zones: npt.NDArray[np.float64],
        window: int,
        max_level: int,
        guided_levels: int,
        limit: float,
        min_points: int,
        rounds: int,
        iterations: int,
        epsilon: float,
        min_eigen: float,
    ) -> None: ...
    def follow(
        self, frame: npt.NDArray[np.uint8], brows: npt.NDArray[np.float64], extra: npt.NDArray[np.float64]
    ) -> tuple[npt.NDArray[np.float64] | None, npt.NDArray[np.float64]]: ...
    def advance(self, step: npt.NDArray[np.float64]) -> bool: ...
    def corners(
        self,
        area: tuple[int, int, int, int],
        mask: npt.NDArray[np.uint8],
        max_corners: int,
        quality: float,
        min_distance: float,
        block: int,
    ) -> npt.NDArray[np.float32]: ...
    def detected(self, points: npt.NDArray[np.float32]) -> None: ...
    def drop_points(self) -> None: ...
    zones: npt.NDArray[np.float64]
    points: tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]
    followed: tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]

def lip_score_map(
    frame: npt.NDArray[np.uint8],
    colour: tuple[float, float, float],
    bounds: tuple[int, int, int, int],
) -> npt.NDArray[np.float32]: ...

class LipPlacer:
    """Moves mouth knots onto lip edges; see ``facemime.track.lips.LipSearch``."""

    def __init__(
        self,
        frame: npt.NDArray[np.uint8],
        colour: tuple[float, float, float],
        reach: float,
        min_step: float,
        index: list[list[int]],
        signs: list[float],
        edges: npt.NDArray[np.float64],
    ) -> None: ...
    def place(
        self,
        frame: npt.NDArray[np.uint8],
        knots: npt.NDArray[np.float64],
        unfollowed: npt.NDArray[np.bool_],
        scale: float,
    ) -> None: ...

def compose(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def grown_box(points: npt.NDArray[np.float64], margin: int, width: int, height: int) -> tuple[int, int, int, int]: ...
def grey_area(image: npt.NDArray[np.uint8], area: tuple[int, int, int, int]) -> npt.NDArray[np.uint8]: ...
def best_match(window: npt.NDArray[np.uint8], template: npt.NDArray[np.uint8]) -> tuple[tuple[int, int], float]: ...
def robust_similarity(
    src: npt.NDArray[np.float64],
    dst: npt.NDArray[np.float64],
    limit: float,
    rounds: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...
def fit_pose(
    model_points: npt.NDArray[np.float64],
    image_points: npt.NDArray[np.float64],
    start: tuple[float, float, float, float, float, float],
    anchor: tuple[float, float],
    prior: float,
    huber: float,
    iterations: int,
) -> tuple[float, float, float, float, float, float]: ...

FIELD_CHANNELS: int

def reported_knots(
    knots: npt.NDArray[np.float64],
    offset: npt.NDArray[np.float64],
    linear: npt.NDArray[np.float64],
    down: tuple[float, float],
    upper: npt.NDArray[np.uintp],
    lower: npt.NDArray[np.uintp],
) -> npt.NDArray[np.float64]: ...
def field_regions(
    knots: npt.NDArray[np.float64],
    bands: list[tuple[npt.NDArray[np.uintp], float]],
    width: int,
    height: int,
    sigma: float,
) -> tuple[tuple[int, int, int, int], list[tuple[int, int, int, int]]]: ...
def frame_field(
    frame: npt.NDArray[np.uint8],
    prev: npt.NDArray[np.uint8] | None,
    region: tuple[int, int, int, int],
    sigma: float,
    bands: list[tuple[int, int, int, int]] | None = None,
    out: npt.NDArray[np.float32] | None = None,
) -> npt.NDArray[np.float32]: ...

class FramePlan:
    def __init__(
        self,
        knots0: npt.NDArray[np.float64],
        down0: tuple[float, float],
        targets0: npt.NDArray[np.float64],
        response0: npt.NDArray[np.float64],
        bounds: tuple[float, float],
        mouth: npt.NDArray[np.uintp],
        mouth_patch: float,
        affine_groups: list[list[int]],
        mouth_affine: float,
        inner: npt.NDArray[np.uintp],
        outer: npt.NDArray[np.uintp],
        centring: float,
        chord_ends: npt.NDArray[np.uintp],
        least_chord: npt.NDArray[np.float64],
        feature_curves: npt.NDArray[np.uintp],
    ) -> None: ...
    def begin(
        self,
        step: npt.NDArray[np.float64],
        total: npt.NDArray[np.float64],
        knots: npt.NDArray[np.float64],
        flow: npt.NDArray[np.float64] | None,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_] | None, bool, float, npt.NDArray[np.float64]]: ...
    def settle(
        self, start: npt.NDArray[np.float64], total: npt.NDArray[np.float64], scale: float
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def rest(self, carried: npt.NDArray[np.float64], start: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def centre(
        self, knots: npt.NDArray[np.float64], rest: npt.NDArray[np.float64], down: tuple[float, float]
    ) -> None: ...
    def shapes(self, knots: npt.NDArray[np.float64], rest: npt.NDArray[np.float64]) -> list[bool]: ...
    def confidences(self, response: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], list[float]]: ...
    def assess(
        self,
        knots: npt.NDArray[np.float64],
        rest: npt.NDArray[np.float64],
        down: tuple[float, float],
        response: npt.NDArray[np.float64],
        carried: npt.NDArray[np.float64],
    ) -> tuple[npt.NDArray[np.float64], list[float], list[bool]]: ...

class SnakeSolver:
    """Curves over one shared knot array, solved jointly by sign descent (see facemime.track)."""

    n_knots: int
    times: tuple[float, float]

    def __init__(
        self,
        curve_knots: npt.NDArray[np.uint32],
        curve_lengths: npt.NDArray[np.uint32],
        curve_params: npt.NDArray[np.float64],
        pairs: npt.NDArray[np.uint32],
        pair_params: npt.NDArray[np.float64],
        points_per_segment: int,
        delta0: float,
        sigma: float,
        iterations: int,
        tol: float,
    ) -> None: ...
    def solve(
        self,
        field: npt.NDArray[np.float32],
        origin: tuple[float, float],
        bounds: tuple[float, float],
        start: npt.NDArray[np.float64],
        rest: npt.NDArray[np.float64],
        down: tuple[float, float],
        pair_targets: npt.NDArray[np.float64],
        curves: npt.NDArray[np.bool_] | None = None,
        held: npt.NDArray[np.bool_] | None = None,
    ) -> tuple[npt.NDArray[np.float64], int, float, npt.NDArray[np.float64]]: ...
    def track(
        self,
        frame: npt.NDArray[np.uint8],
        prev: npt.NDArray[np.uint8] | None,
        start: npt.NDArray[np.float64],
        rest: npt.NDArray[np.float64],
        down: tuple[float, float],
        pair_targets: npt.NDArray[np.float64],
        bounds: tuple[int, int],
        smoothing: float,
        bands: list[tuple[npt.NDArray[np.uintp], float]],
        mouth_knots: npt.NDArray[np.uintp],
        mouth_curves: npt.NDArray[np.bool_],
        passes: int,
        fast: float,
    ) -> tuple[npt.NDArray[np.float64], int, npt.NDArray[np.float64]]: ...
    def evaluate(
        self,
        field: npt.NDArray[np.float32],
        origin: tuple[float, float],
        bounds: tuple[float, float],
        start: npt.NDArray[np.float64],
        rest: npt.NDArray[np.float64],
        down: tuple[float, float],
        pair_targets: npt.NDArray[np.float64],
    ) -> tuple[float, npt.NDArray[np.float64]]: ...

#: (index, face, lost, values, concealed (C, 2) of (first, count), appearance: the appearance
#: payloads in stream order as (frames output before it in this call, payload)).
Decoded = tuple[
    npt.NDArray[np.uint64],
    npt.NDArray[np.bool_],
    npt.NDArray[np.uint8],
    npt.NDArray[np.float64],
    npt.NDArray[np.uint64],
    list[tuple[int, bytes]],
]

class StreamEncoder:
    """The bitstream's encoder (see facemime.codec.stream)."""

    def __init__(
        self,
        fps: tuple[int, int],
        size: tuple[int, int],
        topology: bytes,
        packet_frames: int,
        keyframe_packets: int,
        steps: list[float],
        references: list[int],
        classes: list[int],
        basis: npt.NDArray[np.int16],
        actor_id: bytes,
        actor_in_stream: bool,
        hysteresis: float,
        extras: list[int] = ...,
    ) -> None: ...
    def header_chunk(self) -> bytes: ...
    def push(
        self, face: bool, lost: int, values: npt.NDArray[np.float64]
    ) -> tuple[npt.NDArray[np.float64], bytes | None]: ...
    def finish(self) -> bytes | None: ...
    def next_is_intra(self) -> bool: ...
    def request_intra(self) -> None: ...

def actor_chunk(payload: bytes) -> bytes: ...
def appearance_chunk(payload: bytes) -> bytes: ...
def choose_classes(steps: list[float], hysteresis: float, values: npt.NDArray[np.float64]) -> list[int]: ...

class StreamDecoder:
    """The bitstream's decoder (see facemime.codec.stream)."""

    def __init__(self, from_start: bool) -> None: ...
    def push(self, data: bytes) -> Decoded: ...
    def finish(self) -> Decoded: ...
    def header(self) -> dict | None: ...
    def header_error(self) -> str | None: ...
    def actor(self) -> bytes | None: ...
    def stats(self) -> dict[str, int]: ...
    def pending(self) -> bool: ...
