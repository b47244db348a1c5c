// A test page (not shipped): three.js with three-vrm (npm @pixiv/three-vrm) loads a .vrm written
// by `facemime export --out NAME.vrm` and poses it from one frame of what `facemime live --vmc`
// sends (python/facemime/live/vmc.py), as a VMC receiver would: the head's rotation on the
// humanoid `head` bone, the root's translation on the avatar, the 52 ARKit values as expressions
// by name. It renders a front view with an orthographic camera (the avatar faces +z, towards the
// camera: the subject's left is the picture's right).
// Bundled by `npm run build-vrm-page` into .test-build/vrm-page.js; used by
// tests/export/test_vrm.py and benchmarks/vrm_avatar.py through window.loadVrm, window.applyVmc,
// window.faceVertices and window.toPixels.
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { VRMLoaderPlugin } from "@pixiv/three-vrm";

let vrm = null;
let face = null;
let camera = null;
let renderer = null;

/** Load the .vrm (base64) and frame its face: a `width` x `height` pixel picture of the face's
 * bounding box at rest grown by `margin` (a fraction of its size) on every side, over
 * `background` ([r, g, b] 0-255, sRGB). Resolves to {expressions: the expression manager's names,
 * bones: the humanoid bones' names, meta: the VRM meta, targets: the face's morph target names,
 * head: the head bone's world position at rest (metres)}. */
window.loadVrm = async (base64, { width, height, margin, background }) => {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  const loader = new GLTFLoader();
  loader.register((parser) => new VRMLoaderPlugin(parser));
  const gltf = await loader.parseAsync(bytes.buffer, "");
  vrm = gltf.userData.vrm;
  if (!vrm) throw new Error("three-vrm found no VRM in the file");
  face = null;
  vrm.scene.traverse((o) => { if (o.isMesh && o.material.name === "face") face = o; });  // not the mouth's strip
  vrm.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromPoints(window.faceVertices().map((p) => new THREE.Vector3(...p)));
  const size = box.getSize(new THREE.Vector3());
  const centre = box.getCenter(new THREE.Vector3());
  // the box's larger side, grown by the margin, fills the picture's matching side
  const half = (Math.max(size.x / width, size.y / height) * (1 + 2 * margin)) / 2;
  camera = new THREE.OrthographicCamera(-half * width, half * width, half * height, -half * height, 0.01, 100);
  camera.position.set(centre.x, centre.y, centre.z + 10);
  camera.updateMatrixWorld(true);
  renderer?.dispose();
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  const [r, g, b] = background;
  renderer.setClearColor(new THREE.Color().setRGB(r / 255, g / 255, b / 255, THREE.SRGBColorSpace), 1);
  const head = vrm.humanoid.getRawBoneNode("head").getWorldPosition(new THREE.Vector3());
  return {
    expressions: vrm.expressionManager.expressions.map((e) => e.expressionName),
    bones: Object.keys(vrm.humanoid.humanBones),
    meta: vrm.meta,
    targets: Object.keys(face.morphTargetDictionary ?? {}).sort(
      (a, b2) => face.morphTargetDictionary[a] - face.morphTargetDictionary[b2]),
    head: head.toArray(),
  };
};

/** Pose the avatar from one VMC frame and render it: `head` [qx, qy, qz, qw] in Unity's axes (as
 * /VMC/Ext/Bone/Pos sends it; three's are (x, -y, -z, w)), `root` [x, y, z] metres in Unity's
 * axes (three's: (-x, y, z)), `values` {ARKit name: 0..1}. Resolves to {png: a data URL of the
 * picture, influences: the face's morph target weights, head: the raw head bone's world
 * quaternion [x, y, z, w] in three's axes}. */
window.applyVmc = async ({ head, root, values }) => {
  const [qx, qy, qz, qw] = head;
  vrm.humanoid.getNormalizedBoneNode("head").quaternion.set(qx, -qy, -qz, qw).normalize();
  const [px, py, pz] = root;
  vrm.scene.position.set(-px, py, pz);
  for (const [name, value] of Object.entries(values)) vrm.expressionManager.setValue(name, value);
  vrm.update(1 / 30);
  vrm.scene.updateMatrixWorld(true);
  renderer.render(vrm.scene, camera);
  const q = vrm.humanoid.getRawBoneNode("head").getWorldQuaternion(new THREE.Quaternion());
  return {
    png: renderer.domElement.toDataURL("image/png"),
    influences: Array.from(face.morphTargetInfluences ?? []),
    head: q.toArray(),
  };
};

/** The face's vertices as posed by the last applyVmc, morph targets applied: [[x, y, z], ...],
 * metres in the world (three's axes). */
window.faceVertices = () => {
  const out = [];
  const v = new THREE.Vector3();
  const count = face.geometry.attributes.position.count;
  for (let i = 0; i < count; i++) out.push(face.getVertexPosition(i, v).applyMatrix4(face.matrixWorld).toArray());
  return out;
};

/** World points (metres) to the picture's pixels: [[x right, y down], ...], (0, 0) the centre of
 * the top-left pixel. */
window.toPixels = (points) => {
  const { width, height } = renderer.domElement;
  return points.map(([x, y, z]) => {
    const p = new THREE.Vector3(x, y, z).project(camera);
    return [((p.x + 1) / 2) * width - 0.5, ((1 - p.y) / 2) * height - 0.5];
  });
};
