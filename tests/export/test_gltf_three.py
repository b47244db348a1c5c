"""It plays elsewhere: three.js (npm ``three``, its GLTFLoader and AnimationMixer) in headless
Chromium loads an exported .glb, sets the animation to frame N's time, and renders it with the
orthographic camera the file's ``scenes[0].extras.facemime`` describes; the picture matches
facemime's own render of frame N with ``--mask-only`` (:func:`facemime.animate.synth.synthesize`
of the morphed vertices, in the pose :meth:`Puppet.pose` shows the measured one in) within
:data:`THRESHOLD` dB of PSNR over the face.

The face region is where facemime's mesh covers the picture, less 2 pixels at its rim (the two
rasterisers differ on edge pixels) and less the mouth's opening (facemime paints a cavity and
teeth behind the lips; the file closes it with a dark strip). Measured (Chromium 14x, SwiftShader,
three.js 0.187): 54.9-56.0 dB on the generic head (painted texture), 52.7-56.7 dB on the actor
fitted on lp_d0 with a real track; a frame's picture against another frame's render scores
below 30 dB, a texture flipped upside down below 25 dB.
"""

import base64
from dataclasses import replace

import cv2
import numpy as np
import pytest

from facemime.animate.motion_file import read_motion
from facemime.animate.synth import Puppet, synthesize
from facemime.export import glb_bytes, load_performance
from facemime.io.actor_file import load_actor
from facemime.render.raster import coverage
from facemime.shared_constants import BACKGROUND
from facemime.types.pose import Pose, project

#: Least PSNR (dB) of three.js's picture against facemime's over the face: the measured values
#: (module docstring) less a margin of about 4 dB for other Chromium and three.js versions.
THRESHOLD = 48.0


@pytest.fixture(scope="module")
def three(browser, three_page):
    """A page with the three.js test page loaded; call ``render(glb bytes, seconds)``."""
    context = browser.new_context()
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.set_content("<!doctype html><html><body></body></html>")
    page.add_script_tag(content=three_page)

    def render(data: bytes, seconds: float):
        out = page.evaluate(
            "([b, t, bg]) => renderGlb(b, t, bg)", [base64.b64encode(data).decode(), float(seconds), list(BACKGROUND)]
        )
        png = np.frombuffer(base64.b64decode(out["png"].split(",", 1)[1]), np.uint8)
        return cv2.cvtColor(cv2.imdecode(png, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB), out

    yield render
    context.close()
    assert not errors, errors


def facemime_frame(track, perf, n):
    """facemime's mask-only render of frame ``n`` of the exported performance, and the face region."""
    _, block, frames = read_motion(track)
    puppet = Puppet(perf.actor, np.asarray(block["feature_sizes"]), block["iod"], None, mask_only=True)
    pose = puppet.pose(Pose(**frames[n]["pose"]))
    vertices = perf.actor.model.vertices + np.tensordot(perf.weights[n], perf.fields, axes=1)  # the morph
    picture = synthesize(perf.actor, vertices, pose, perf.size)
    points = project(vertices, pose)[0]
    g = perf.actor.model.groups
    face = (coverage(points, perf.actor.model.triangles, perf.size) > 0).astype(np.uint8)
    mouth = np.zeros_like(face)
    cv2.fillPoly(
        mouth,
        [
            np.round(np.concatenate([points[g["mouth_inner_upper"]], points[g["mouth_inner_lower"]][::-1]])).astype(
                np.int32
            )
        ],
        1,
    )
    kernel = np.ones((5, 5), np.uint8)
    return picture, (cv2.erode(face, kernel) > 0) & ~(cv2.dilate(mouth, kernel) > 0)


def psnr(a, b, region):
    d = a.astype(np.float64)[region] - b[region]
    return 10 * np.log10(255.0**2 / max(float(np.mean(d**2)), 1e-12))


def check_frames(three, track, perf, data, frames):
    scores = []
    for n in frames:
        picture, out = three(data, perf.times[n])
        assert out["names"] == list(perf.names) and np.allclose(out["weights"], perf.weights[n], atol=1e-5)
        reference, region = facemime_frame(track, perf, n)
        assert region.sum() > 5000
        scores.append(psnr(picture, reference, region))
    print(f"three.js against facemime, frames {frames}: " + ", ".join(f"{s:.1f}" for s in scores) + " dB")
    assert min(scores) >= THRESHOLD, scores
    return scores


def test_the_generic_head_plays_in_three_js_as_facemime_draws_it(three, generic_export):
    track, glb = generic_export
    perf = load_performance(track)
    data = glb.read_bytes()
    check_frames(three, track, perf, data, [0, 4, 11])  # 11: the clip's end (played once, not wrapped)
    picture, _ = three(data, perf.times[4])  # a frame against another frame's render: far off
    other, region = facemime_frame(track, perf, 9)
    print(f"frame 4 against frame 9: {psnr(picture, other, region):.1f} dB")
    assert psnr(picture, other, region) < 30.0
    flipped = replace(
        perf, actor=replace(perf.actor, model=replace(perf.actor.model, uv=perf.actor.model.uv * [1, -1] + [0, 1]))
    )
    picture, _ = three(glb_bytes(flipped), perf.times[4])  # a v flip would show
    reference, region = facemime_frame(track, perf, 4)
    print(f"texture flipped upside down: {psnr(picture, reference, region):.1f} dB")
    assert psnr(picture, reference, region) < 25.0


def test_a_fitted_actor_with_a_real_track_plays_in_three_js_as_facemime_draws_it(three, real_export):
    track, actor, glb = real_export
    perf = load_performance(track, load_actor(actor))
    check_frames(three, track, perf, glb.read_bytes(), [3, 7, 11])
