"""Finding the face: the largest of several, and the clean error where there is no human face."""

from concurrent.futures import ThreadPoolExecutor

import cv2
import numpy as np
import pytest

from facemime.errors import FacemimeError, NoFaceError
from facemime.io.photo import read_photo
from facemime.networks import find_face
from facemime.networks.network import MODELS, load_network


@pytest.mark.parametrize("name", ["lp_s22", "lp_s25", "lp_s39"])  # a monkey, a dog, a cat
def test_an_animal_is_no_human_face(shared, name):
    with pytest.raises(NoFaceError, match=r"^no face found$"):
        find_face(read_photo(shared / "photos" / f"{name}.jpg"))


@pytest.mark.parametrize("value", [0, 128, 255])
def test_a_blank_image_has_no_face(value):
    with pytest.raises(NoFaceError, match="no face found"):
        find_face(np.full((300, 400, 3), value, np.uint8))


def test_the_largest_of_two_faces_is_taken_and_both_are_counted(shared):
    canvas = np.full((520, 960, 3), 200, np.uint8)
    big = cv2.resize(read_photo(shared / "photos" / "lp_s42.jpg"), (480, 480), interpolation=cv2.INTER_AREA)
    small = cv2.resize(read_photo(shared / "photos" / "lp_s1.jpg"), (400, 400), interpolation=cv2.INTER_AREA)
    canvas[20:500, 460:940] = big
    canvas[60:460, 20:420] = small
    face = find_face(canvas)
    assert face.faces == 2
    assert (face.landmarks[:, 0] > 460).all()  # on the larger face, the right one


def test_threads_finding_faces_at_once_each_get_the_one_thread_answer(shared):
    """A network is not shared between threads (call's sender analyses while the main thread may
    fit the next actor): OpenCV 5.1 failed an assertion, or a pass read another's input."""
    photo = read_photo(shared / "photos" / "lp_s42.jpg")
    alone = find_face(photo).landmarks
    with ThreadPoolExecutor(4) as pool:
        found = list(pool.map(lambda _: find_face(photo).landmarks, range(12)))
    assert all(np.array_equal(f, alone) for f in found)


def test_the_shipped_models_load_and_an_unknown_one_is_refused():
    for name in MODELS:
        assert not load_network(name).empty()
    with pytest.raises(FacemimeError, match=r"unknown face model 'x.tflite'"):
        load_network("x.tflite")


def test_the_shipped_models_are_the_files_their_readme_names():
    import hashlib
    import re
    from importlib import resources

    folder = resources.files("facemime.networks") / "models"
    rows = re.findall(r"\| `([\w.]+\.tflite)` \| (\d+) \| `([0-9a-f]{64})` \|", (folder / "README.md").read_text())
    assert sorted(name for name, _, _ in rows) == sorted(MODELS)
    for name, size, digest in rows:
        data = (folder / name).read_bytes()
        assert len(data) == int(size) and hashlib.sha256(data).hexdigest() == digest, name
    assert "Apache License" in (folder / "LICENSE").read_text()
