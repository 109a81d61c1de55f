// What the spinviz page takes from three.js (bundled into three.min.js: see README.md here).
export {
  AmbientLight, AnimationMixer, Color, DirectionalLight, LoopOnce, PerspectiveCamera, Scene, Vector2, Vector3, WebGLRenderer,
} from 'three';
export { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
