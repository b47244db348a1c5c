// A test page (not shipped): three.js loads a .glb written by `facemime export`, sets its
// animation to a given time and renders it with the orthographic camera that the file's
// scenes[0].extras.facemime describes (the video's size, metres per pixel, the pixel on the
// world origin), so that the picture lines up with facemime's own render of that frame.
// Bundled by `npm run build-gltf-page` into .test-build/gltf-page.js; used by
// tests/export/test_gltf_three.py through window.renderGlb.
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";

/** Render the .glb (base64) at `time` seconds over `background` ([r, g, b] 0-255, sRGB);
 * resolves to {png: a data URL of the picture, names: the morph target names, weights: the
 * morph weights at that time, duration: the animation's length, seconds}. */
window.renderGlb = async (base64, time, background) => {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  const gltf = await new GLTFLoader().parseAsync(bytes.buffer, "");
  const { size, metres_per_pixel: m, origin } = gltf.scene.userData.facemime;
  const [w, h] = size;
  const [tx, ty] = origin;
  const camera = new THREE.OrthographicCamera((-0.5 - tx) * m, (w - 0.5 - tx) * m, (ty + 0.5) * m,
    (ty + 0.5 - h) * m, 0.01, 100);
  camera.position.set(0, 0, 10);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const clip = gltf.animations[0];
  const action = mixer.clipAction(clip);
  action.setLoop(THREE.LoopOnce, 1); // at the clip's end, stay on the last frame (no wrap to the first)
  action.clampWhenFinished = true;
  action.play();
  mixer.setTime(time);
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(w, h);
  const [r, g, b] = background;
  renderer.setClearColor(new THREE.Color().setRGB(r / 255, g / 255, b / 255, THREE.SRGBColorSpace), 1);
  renderer.render(gltf.scene, camera);
  let mesh = null;
  gltf.scene.traverse((o) => { if (o.isMesh && o.material.name === "face") mesh = o; });  // not the mouth's strip
  const names = Object.keys(mesh.morphTargetDictionary ?? {}).sort(
    (a, b2) => mesh.morphTargetDictionary[a] - mesh.morphTargetDictionary[b2]);
  const png = renderer.domElement.toDataURL("image/png");
  renderer.dispose();
  return { png, names, weights: Array.from(mesh.morphTargetInfluences ?? []), duration: clip.duration };
};
