// glint's scene viewer: loads a reconstruction's scene.glb (glTF 2.0: one material per segment
// with KHR_materials_specular and the Ward values in extras, a _SEGMENT vertex attribute, the
// estimated lights as KHR_lights_punctual point lights) and shows it relit by those lights.
//
// URL parameters (all optional):
//   glb=PATH            the file to load (default scene.glb, beside the page)
//   view=NAME           shaded | albedo | diffuse | specular | segments (default shaded)
//   exposure=X          pixel = radiance × X, clipped to [0, 1] (default: the file's
//                       scenes[0].extras.glint.exposure, else 1); glint's re-renderings do the same
//   intrinsics=fx,fy,cx,cy,width,height
//   world_to_camera=m00,m01,...,m33
//                       render from a camera of glint's: pinhole intrinsics in pixels (pixel
//                       centres at integer coordinates) and the 4×4 world-to-camera matrix, row
//                       major, in glint's world frame and OpenCV camera axes (x right, y down,
//                       z forward). The viewer maps it through the file's root node (glint's
//                       world → glTF's +Y-up axes) and into three.js's camera axes (x right, y up,
//                       looking down −z). The canvas is then exactly width × height pixels.
//   clean=1             no panel and no light handles (screenshots)
//   background=RRGGBB   background colour (default 000000, as glint's re-renderings)
// window.glintViewer reports the state for scripts: {state: 'loading' | 'ready' | 'error',
// error, segments, lights, triangles}.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';

const params = new URLSearchParams(window.location.search);
const report = { state: 'loading', error: null, segments: 0, lights: 0, triangles: 0 };
window.glintViewer = report;

const statusLine = document.getElementById('status');
const clean = params.get('clean') === '1';
if (clean) document.body.classList.add('clean');

function fail(message) {
  report.state = 'error';
  report.error = message;
  document.body.dataset.state = 'error';
  statusLine.textContent = message;
  console.error(`glint viewer: ${message}`);
}

function numbers(name, count) {
  const text = params.get(name);
  if (text === null) return null;
  const values = text.split(',').map(Number);
  if (values.length !== count || values.some((v) => !Number.isFinite(v)))
    throw new Error(`URL parameter ${name} needs ${count} comma-separated numbers`);
  return values;
}

let intrinsics = null, worldToCamera = null;
try {
  intrinsics = numbers('intrinsics', 6);
  worldToCamera = numbers('world_to_camera', 16);
  if ((intrinsics === null) !== (worldToCamera === null))
    throw new Error('URL parameters intrinsics and world_to_camera go together');
} catch (error) {
  fail(error.message);
  intrinsics = worldToCamera = null;
}
const fixedCamera = intrinsics !== null;

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.SRGBColorSpace;
// Linear tone mapping is saturate(exposure × radiance): glint's re-rendering (radiance times the
// sequence's exposure, clipped), before the sRGB encoding both apply.
renderer.toneMapping = THREE.LinearToneMapping;
if (fixedCamera) {
  renderer.setPixelRatio(1);
  renderer.setSize(intrinsics[4], intrinsics[5]);
} else {
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
}
document.body.prepend(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(`#${params.get('background') ?? '000000'}`);
const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.01, 100);

let renderQueued = false;
function requestRender() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    renderer.render(scene, camera);
  });
}

const orbit = new OrbitControls(camera, renderer.domElement);
orbit.addEventListener('change', requestRender);
const mover = new TransformControls(camera, renderer.domElement);
mover.addEventListener('change', requestRender);
mover.addEventListener('dragging-changed', (event) => { orbit.enabled = !event.value; });
scene.add(mover.getHelper());

// --- views -----------------------------------------------------------------------------------

// glint's segment colours (apps/glint/reconstruct_outputs.cpp): golden-ratio hue steps at full
// saturation, black for segment 0 (no segment), as sRGB.
function segmentColour(id) {
  if (id <= 0) return new THREE.Color(0, 0, 0);
  const hue = ((id * 0.618034) % 1) * 6;
  const f = hue - Math.floor(hue);
  const sextants = [[1, f, 0], [1 - f, 1, 0], [0, 1, f], [0, 1 - f, 1], [f, 0, 1], [1, 0, 1 - f]];
  const [r, g, b] = sextants[Math.min(5, Math.floor(hue))];
  return new THREE.Color().setRGB(r, g, b, THREE.SRGBColorSpace);
}

// The Ward parameters a material carries in its extras: {ward: {kd, ks, alpha}} or the fields
// at the top level.
function wardOf(material) {
  const extras = material?.userData ?? {};
  const ward = extras.ward ?? extras;
  if (ward.kd === undefined && ward.ks === undefined && ward.alpha === undefined) return null;
  return { segment: extras.segment ?? ward.segment, kd: ward.kd, ks: ward.ks, alpha: ward.alpha };
}

// Per mesh: its materials and geometry as loaded, and the other views built from them once.
const meshes = [];
const wardBySegment = new Map();

function segmentOfVertex(entry, vertex) {
  const attribute = entry.geometry.getAttribute('_segment');
  if (attribute) return Math.round(attribute.getX(vertex));
  return wardOf(entry.material)?.segment ?? 0;
}

function buildViews(entry) {
  const m = entry.material;
  const colourOf = { color: m.color, map: m.map, vertexColors: m.vertexColors };
  const specular = m.clone();
  specular.color = new THREE.Color(0, 0, 0);
  specular.map = null;
  specular.vertexColors = false;
  // Segment colours as a second geometry over the same vertices (positions and indices shared).
  const geometry = entry.geometry;
  const coloured = new THREE.BufferGeometry();
  coloured.setIndex(geometry.index);
  coloured.setAttribute('position', geometry.getAttribute('position'));
  const colours = new Float32Array(geometry.getAttribute('position').count * 3);
  for (let v = 0; v < colours.length / 3; ++v)
    segmentColour(segmentOfVertex(entry, v)).toArray(colours, 3 * v);
  coloured.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  entry.views = {
    shaded: [m, geometry],
    albedo: [new THREE.MeshBasicMaterial(colourOf), geometry],
    diffuse: [new THREE.MeshLambertMaterial(colourOf), geometry],
    specular: [specular, geometry],
    segments: [new THREE.MeshBasicMaterial({ vertexColors: true }), coloured],
  };
}

function showView(name) {
  for (const entry of meshes) {
    const [material, geometry] = entry.views[name] ?? entry.views.shaded;
    entry.mesh.material = material;
    entry.mesh.geometry = geometry;
  }
  requestRender();
}

for (const input of document.querySelectorAll('input[name=view]')) {
  input.addEventListener('change', () => showView(input.value));
}

// --- lights ----------------------------------------------------------------------------------

const handles = [];

function addLightControls(light, index, handleRadius) {
  const handle = new THREE.Mesh(
    new THREE.SphereGeometry(handleRadius, 16, 8),
    new THREE.MeshBasicMaterial({ color: light.color }),
  );
  handle.userData.light = light;
  handle.visible = !clean;
  light.add(handle);
  handles.push(handle);

  const original = light.intensity;
  const row = document.createElement('label');
  const toggle = document.createElement('input');
  toggle.type = 'checkbox';
  toggle.checked = true;
  const slider = document.createElement('input');
  slider.type = 'range';
  slider.min = '0';
  slider.max = '4';
  slider.step = '0.05';
  slider.value = '1';
  const name = document.createElement('span');
  const describe = () => {
    const p = light.getWorldPosition(new THREE.Vector3());
    name.textContent = ` ${light.name || `light ${index}`} ×${Number(slider.value).toFixed(2)} ` +
      `(${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${p.z.toFixed(2)})`;
  };
  const apply = () => {
    light.intensity = toggle.checked ? original * Number(slider.value) : 0;
    describe();
    requestRender();
  };
  toggle.addEventListener('change', apply);
  slider.addEventListener('input', apply);
  mover.addEventListener('objectChange', () => { if (mover.object === light) describe(); });
  row.append(toggle, name, slider);
  document.getElementById('lights').append(row);
  describe();
}

const exposureSlider = document.getElementById('exposure');
let baseExposure = 1;
function applyExposure() {
  const stops = Number(exposureSlider.value);
  renderer.toneMappingExposure = baseExposure * 2 ** stops;
  document.getElementById('exposure-value').textContent =
    `${renderer.toneMappingExposure.toPrecision(3)} (${stops >= 0 ? '+' : ''}${stops} stops)`;
  requestRender();
}
exposureSlider.addEventListener('input', applyExposure);

// --- camera ----------------------------------------------------------------------------------

// A camera of glint's (intrinsics, world-to-camera in glint's world and OpenCV axes) as a
// three.js camera under `worldRoot`, the node that maps glint's world to glTF's.
function placeFixedCamera(worldRoot) {
  const [fx, fy, cx, cy, width, height] = intrinsics;
  const near = 0.01, far = 100;
  // OpenGL projection of the pinhole camera; with pixel centres at integer coordinates the image
  // spans [-0.5, width - 0.5], so NDC x = 2 (u + 0.5) / width - 1 (and y flipped).
  camera.projectionMatrix.set(
    2 * fx / width, 0, 1 - 2 * (cx + 0.5) / width, 0,
    0, 2 * fy / height, 2 * (cy + 0.5) / height - 1, 0,
    0, 0, -(far + near) / (far - near), -2 * far * near / (far - near),
    0, 0, -1, 0);
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  // view = flip(y, z) · world_to_camera · root⁻¹ (glTF world → glint world → OpenCV camera →
  // three.js camera).
  const view = new THREE.Matrix4().makeScale(1, -1, -1)
    .multiply(new THREE.Matrix4().set(...worldToCamera))
    .multiply(worldRoot.matrixWorld.clone().invert());
  const cameraToWorld = view.clone().invert();
  cameraToWorld.decompose(camera.position, camera.quaternion, camera.scale);
  camera.updateMatrixWorld(true);
  // Orbiting starts from this pose about a point 1 m ahead.
  orbit.target.copy(new THREE.Vector3(0, 0, -1).applyMatrix4(cameraToWorld));
}

function frameBounds(box) {
  const centre = box.getCenter(new THREE.Vector3());
  const radius = box.getSize(new THREE.Vector3()).length() / 2 || 1;
  camera.near = radius / 100;
  camera.far = radius * 20;
  camera.position.copy(centre).add(new THREE.Vector3(0, radius * 0.6, radius * 1.8));
  camera.updateProjectionMatrix();
  orbit.target.copy(centre);
  orbit.update();
}

window.addEventListener('resize', () => {
  if (fixedCamera) return;
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
  requestRender();
});

// --- picking ---------------------------------------------------------------------------------

const raycaster = new THREE.Raycaster();
let pressedAt = null;
renderer.domElement.addEventListener('pointerdown', (event) => {
  pressedAt = [event.clientX, event.clientY];
});
renderer.domElement.addEventListener('pointerup', (event) => {
  if (!pressedAt || Math.hypot(event.clientX - pressedAt[0], event.clientY - pressedAt[1]) > 4)
    return;  // a drag (orbit or light move), not a click
  const rect = renderer.domElement.getBoundingClientRect();
  const pointer = new THREE.Vector2(
    ((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const handleHit = raycaster.intersectObjects(handles.filter((h) => h.visible), false)[0];
  if (handleHit) {
    mover.attach(handleHit.object.userData.light);
    requestRender();
    return;
  }
  const hit = raycaster.intersectObjects(meshes.map((e) => e.mesh), false)[0];
  if (!hit) {
    mover.detach();
    requestRender();
    return;
  }
  const entry = meshes.find((e) => e.mesh === hit.object);
  const segment = segmentOfVertex(entry, hit.face.a);
  showPicked(segment, wardOf(entry.material) ?? wardBySegment.get(segment), entry.material);
});

function triple(values) {
  return Array.isArray(values) ? values.map((v) => Number(v).toFixed(3)).join(' ') : '–';
}

function showPicked(segment, ward, material) {
  const lines = [`segment ${segment}`];
  if (ward) {
    lines.push(`κd ${triple(ward.kd)}`, `κs ${triple(ward.ks)}`,
      `α  ${ward.alpha !== undefined ? Number(ward.alpha).toFixed(3) : '–'}`);
  } else {
    lines.push('no Ward parameters (segment without a material)');
  }
  lines.push(`glTF roughness ${material.roughness?.toFixed(3) ?? '–'}`);
  if (material.specularIntensity !== undefined)
    lines.push(`glTF specular ${material.specularIntensity.toFixed(3)} × ` +
      `${triple(material.specularColor?.toArray())}`);
  document.getElementById('picked').textContent = lines.join('\n');
}

// --- loading ---------------------------------------------------------------------------------

// The node that maps glint's world to glTF's: the scene's single top-level node (identity when
// the scene has several).
function worldRootOf(root) {
  return root.children.length === 1 ? root.children[0] : root;
}

async function main() {
  if (report.state === 'error') return;
  const url = params.get('glb') ?? 'scene.glb';
  const gltf = await new GLTFLoader().loadAsync(url);
  const root = gltf.scene;
  scene.add(root);
  root.updateMatrixWorld(true);

  const segments = new Set();
  root.traverse((object) => {
    if (!object.isMesh) return;
    const entry = { mesh: object, material: object.material, geometry: object.geometry };
    const ward = wardOf(object.material);
    if (ward?.segment !== undefined) wardBySegment.set(ward.segment, ward);
    meshes.push(entry);
    const index = object.geometry.index;
    report.triangles += (index ? index.count : object.geometry.getAttribute('position').count) / 3;
  });
  for (const entry of meshes) {
    buildViews(entry);
    const attribute = entry.geometry.getAttribute('_segment');
    if (attribute) for (let v = 0; v < attribute.count; ++v) segments.add(attribute.getX(v));
    else segments.add(wardOf(entry.material)?.segment ?? 0);
  }
  report.segments = segments.size;

  const box = new THREE.Box3().setFromObject(root);
  const handleRadius = Math.max(0.01, box.getSize(new THREE.Vector3()).length() * 0.01);
  const lights = [];
  root.traverse((object) => { if (object.isLight) lights.push(object); });
  lights.forEach((light, k) => addLightControls(light, k, handleRadius));
  report.lights = lights.length;

  baseExposure =
    Number(params.get('exposure') ?? gltf.parser.json.scenes?.[0]?.extras?.glint?.exposure ?? 1);
  applyExposure();

  if (fixedCamera) placeFixedCamera(worldRootOf(root));
  else frameBounds(box);
  showView(params.get('view') ?? 'shaded');
  const checked = document.querySelector(`input[name=view][value=${params.get('view') ?? 'shaded'}]`);
  if (checked) checked.checked = true;

  statusLine.textContent = `${report.triangles.toLocaleString()} triangles, ` +
    `${report.segments} segments, ${report.lights} lights`;
  // Ready once the first frame is drawn.
  requestAnimationFrame(() => {
    renderer.render(scene, camera);
    report.state = 'ready';
    document.body.dataset.state = 'ready';
  });
}

main().catch((error) => fail(`cannot show ${params.get('glb') ?? 'scene.glb'}: ${error.message ?? error}`));
