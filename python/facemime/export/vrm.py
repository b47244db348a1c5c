"""``facemime export --out NAME.vrm``: the actor's head as a VRM 1.0 avatar, a binary glTF 2.0
file with the ``VRMC_vrm`` extension (https://github.com/vrm-c/vrm-specification,
``specification/VRMC_vrm-1.0``) that avatar software (VSeeFace, Warudo, VNyan, three-vrm in the
browser) drives from the VMC messages of ``facemime live`` (:mod:`facemime.live.vmc`).

What it holds:

- the **face**: the same mesh, texture, unlit material and 52 ARKit morph targets as the
  ``.glb`` (:func:`facemime.export.performance.add_face`), the targets at rest weight 0, on a
  node parented under the ``head`` bone;
- a **humanoid skeleton** of the bones VRM 1.0 requires (:data:`BONES`: hips, spine, head, upper
  and lower arms and hands, upper and lower legs and feet), in the VRM T-pose: standing at the
  origin facing +z, arms along x, every rotation the identity. Only the head has a mesh (a
  head-only avatar); the other bones are there for the software that needs a whole humanoid.
  The head bone sits on the model's origin, :data:`HEAD_HEIGHT` metres above the ground: the
  point facemime's pose turns the head about (:func:`facemime.types.pose.rotation_matrix`) and
  whose shift ``live`` sends as the root's translation, so that a receiver that applies both
  shows the head moving as facemime measures it (a real neck turns the head about a point lower
  and further back, where avatars modelled by hand have their head bone);
- ``meta``: the actor model's name, author ``facemime``, the VRM 1.0 licence
  (:data:`LICENCE`) and its most restrictive choices (:data:`PERMISSIONS`: only the author may
  act with the avatar, personal non-profit use, credit required, no redistribution or
  modification), because the face is a real person's;
- ``expressions``: one custom expression per ARKit name (52, each binding its own morph target
  with weight 1: ``expressionManager.setValue("jawOpen", 0.7)`` in three-vrm), and the presets
  ARKit has an evident match for (:data:`PRESETS`: ``blink``, ``blinkLeft``, ``blinkRight``,
  ``aa``); the others (emotions, the other vowels, the look directions) are left out.

Axes and units are glTF's and VRM's, the same as the model's: x to the subject's left (the
avatar's left, VRM's +x), y up, z the way the face looks; metres.

The performance's **animation is kept** (it costs the file its keys only): the ``.glb``'s, one
linear animation of the face's node (its rotation, translation and scale under the head bone)
and of the 52 weights. VRM software ignores animations
(the specification lists them as unused) and poses the avatar itself; a plain glTF player
(three.js's ``AnimationMixer`` on the loaded scene) plays the performance.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from facemime import __version__
from facemime.export.gltf import Glb
from facemime.export.performance import Performance, add_animation, add_face

#: The URL of the VRM Public License 1.0 that ``meta.licenseUrl`` must name.
LICENCE = "https://vrm.dev/licenses/1.0/"
#: The licence's choices written: all the most restrictive (the defaults of VRM 1.0).
PERMISSIONS: dict[str, Any] = {
    "avatarPermission": "onlyAuthor",
    "allowExcessivelyViolentUsage": False,
    "allowExcessivelySexualUsage": False,
    "commercialUsage": "personalNonProfit",
    "allowPoliticalOrReligiousUsage": False,
    "allowAntisocialOrHateUsage": False,
    "creditNotation": "required",
    "allowRedistribution": False,
    "modification": "prohibited",
}
#: Height of the head bone (the model's origin, at about the eyes) above the ground, metres.
HEAD_HEIGHT = 1.55
#: The humanoid bones VRM 1.0 requires: (name, parent, rest position in metres: x to the avatar's
#: left, y up from the ground, z forward), a parent always listed before its children.
BONES: tuple[tuple[str, str | None, tuple[float, float, float]], ...] = (
    ("hips", None, (0.0, 0.95, 0.0)),
    ("spine", "hips", (0.0, 1.05, 0.0)),
    ("head", "spine", (0.0, HEAD_HEIGHT, 0.0)),
    ("leftUpperArm", "spine", (0.17, 1.37, 0.0)),
    ("leftLowerArm", "leftUpperArm", (0.45, 1.37, 0.0)),
    ("leftHand", "leftLowerArm", (0.70, 1.37, 0.0)),
    ("rightUpperArm", "spine", (-0.17, 1.37, 0.0)),
    ("rightLowerArm", "rightUpperArm", (-0.45, 1.37, 0.0)),
    ("rightHand", "rightLowerArm", (-0.70, 1.37, 0.0)),
    ("leftUpperLeg", "hips", (0.09, 0.90, 0.0)),
    ("leftLowerLeg", "leftUpperLeg", (0.09, 0.50, 0.0)),
    ("leftFoot", "leftLowerLeg", (0.09, 0.08, 0.0)),
    ("rightUpperLeg", "hips", (-0.09, 0.90, 0.0)),
    ("rightLowerLeg", "rightUpperLeg", (-0.09, 0.50, 0.0)),
    ("rightFoot", "rightLowerLeg", (-0.09, 0.08, 0.0)),
)
#: Preset expressions and the ARKit names each binds (weight 1 each).
PRESETS: dict[str, tuple[str, ...]] = {
    "blink": ("eyeBlinkLeft", "eyeBlinkRight"),
    "blinkLeft": ("eyeBlinkLeft",),
    "blinkRight": ("eyeBlinkRight",),
    "aa": ("jawOpen",),
}


def _expression(binds: list[dict[str, Any]]) -> dict[str, Any]:
    """A VRM expression of morph target binds, continuous, overriding nothing."""
    return {
        "morphTargetBinds": binds,
        "isBinary": False,
        "overrideBlink": "none",
        "overrideLookAt": "none",
        "overrideMouth": "none",
    }


def vrm_bytes(perf: Performance) -> bytes:
    """The ``.vrm`` file of a performance's head (see the module docstring).

    Parameters
    ----------
    perf
        The performance: its actor's mesh, texture and morph targets become the avatar's face,
        its frames the file's animation.

    Returns
    -------
    bytes
        A binary glTF 2.0 file with ``VRMC_vrm`` 1.0; metres, the avatar facing +z.
    """
    model = perf.actor.model
    g = Glb(f"facemime {__version__}")
    mesh = add_face(g, perf)
    if perf.names:
        g.doc["meshes"][mesh]["weights"] = [0.0] * len(perf.names)  # at rest: neutral
    face = g.add("nodes", {"name": model.name or "face", "mesh": mesh})  # in the head bone's frame
    root = g.add("nodes", {"name": "root"})
    nodes: dict[str, int] = {}
    children: dict[int, list[int]] = {}
    places = {name: np.array(at) for name, _, at in BONES}
    for name, parent, _ in BONES:
        local = places[name] - (places[parent] if parent else 0.0)
        nodes[name] = g.add("nodes", {"name": name, "translation": [float(x) for x in local]})
        children.setdefault(nodes[parent] if parent else root, []).append(nodes[name])
    children[nodes["head"]] = [face]
    for k, kids in children.items():  # glTF: a node's children, when it has any
        g.doc["nodes"][k]["children"] = kids
    g.doc["scenes"] = [{"name": "avatar", "nodes": [root]}]
    g.doc["scene"] = 0
    slot = {name: k for k, name in enumerate(perf.names)}

    def binds(names: tuple[str, ...]) -> list[dict[str, Any]]:
        return [{"node": face, "index": slot[n], "weight": 1.0} for n in names]

    g.doc["extensionsUsed"].append("VRMC_vrm")
    g.doc["extensions"] = {
        "VRMC_vrm": {
            "specVersion": "1.0",
            "meta": {
                "name": model.name or "facemime head",
                "authors": ["facemime"],
                "licenseUrl": LICENCE,
                **PERMISSIONS,
            },
            "humanoid": {"humanBones": {name: {"node": k} for name, k in nodes.items()}},
            "expressions": {
                "preset": {
                    preset: _expression(binds(names))
                    for preset, names in PRESETS.items()
                    if all(n in slot for n in names)
                },
                "custom": {name: _expression(binds((name,))) for name in perf.names},
            },
        }
    }
    add_animation(g, perf, face)
    return g.bytes()
