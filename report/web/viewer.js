// The 3-D needle view of mneedle's HTML report: one WebGL canvas, a list to pick the needle,
// turned with the mouse (OrbitControls). The needles arrive as JSON in the page
// (<script id="mneedle-needles">, written by report/src/html_report.cpp): millimetres in the
// needle frame, tip at the origin, axis +z. Everything here is bundled into the page by esbuild:
// the page opens offline and fetches nothing. docs/cli.md, "Reports".
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

function readNeedles() {
  const node = document.getElementById('mneedle-needles');
  if (!node) return [];
  return JSON.parse(node.textContent);
}

function geometryOf(needle) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(needle.positions, 3));
  geometry.setIndex(needle.indices);
  // Flat shading from face normals: a faceted STL should look faceted, not smoothed.
  const flat = geometry.toNonIndexed();
  flat.computeVertexNormals();
  return flat;
}

function start() {
  const host = document.getElementById('needle-view');
  const needles = readNeedles();
  if (!host || needles.length === 0) return;
  const select = document.getElementById('needle-select');
  const caption = document.getElementById('needle-caption');

  let renderer;
  try {
    // preserveDrawingBuffer: the page can be printed or captured as it is shown.
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    host.textContent = 'This browser cannot show the 3-D view (no WebGL): ' + e.message;
    return;
  }
  const width = host.clientWidth || 640;
  const height = 420;
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(width, height);
  renderer.setClearColor(0xf7f7f7);
  host.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(1, -2, 3);
  scene.add(sun);

  const camera = new THREE.PerspectiveCamera(35, width / height, 1e-4, 1e3);
  camera.up.set(0, 0, 1);  // the needle axis is z
  const controls = new OrbitControls(camera, renderer.domElement);
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);

  const material = new THREE.MeshStandardMaterial({
    color: 0x8a9bb0, metalness: 0.35, roughness: 0.45, side: THREE.DoubleSide,
  });
  let shown = null;

  function show(index) {
    const needle = needles[index];
    if (shown) {
      scene.remove(shown);
      shown.traverse((o) => { if (o.geometry) o.geometry.dispose(); });
    }
    const group = new THREE.Group();
    group.add(new THREE.Mesh(geometryOf(needle), material));
    const box = new THREE.Box3().setFromObject(group);
    const size = box.getSize(new THREE.Vector3());
    const centre = box.getCenter(new THREE.Vector3());
    // The tissue surface at the tip (z = 0) as a thin ring of grid, for scale and orientation.
    const span = Math.max(size.x, size.y, size.z);
    const grid = new THREE.GridHelper(span * 1.5, 10, 0xb0b0b0, 0xd8d8d8);
    grid.rotation.x = Math.PI / 2;
    group.add(grid);
    scene.add(group);
    shown = group;

    const radius = 0.5 * Math.hypot(size.x, size.y, size.z) || 1;
    controls.target.copy(centre);
    const distance = radius / Math.sin((camera.fov * Math.PI) / 360) * 1.1;
    camera.position.set(centre.x + distance * 0.8, centre.y - distance * 0.5, centre.z + distance * 0.3);
    camera.near = distance / 100;
    camera.far = distance * 100;
    camera.updateProjectionMatrix();
    controls.update();
    if (caption) {
      caption.textContent = needle.name + ': ' + needle.triangles + ' triangles, ' +
        size.x.toPrecision(3) + ' × ' + size.y.toPrecision(3) + ' × ' + size.z.toPrecision(3) +
        ' mm (drag to turn, wheel to zoom)';
    }
    render();
  }

  if (select) {
    select.addEventListener('change', () => show(Number(select.value)));
  }
  for (const row of document.querySelectorAll('[data-needle]')) {
    row.addEventListener('click', () => {
      const index = Number(row.dataset.needle);
      if (select) select.value = String(index);
      show(index);
      host.scrollIntoView({ behavior: 'smooth', block: 'nearest' });
    });
  }
  show(0);
  // For the browser test (report/tests/check_report.mjs) and for anyone scripting the page.
  document.body.dataset.viewer = 'rendered';
}

if (document.readyState === 'loading') {
  document.addEventListener('DOMContentLoaded', start);
} else {
  start();
}
