// Lacuna's report page: the run's report.json as tables, and every exported object in a 3D viewer
// (orbit, zoom, wireframe, a section plane along the build direction, printability markers). The
// page is one file: report.json, the meshes (Draco, base64), the pictures (PNG, base64) and this
// script (three.js and Draco's decoder, bundled) are all inside it, so it opens from file:// and
// makes no request.
//
// What the page did is kept in window.lacunaPage (and as JSON in #lacuna-page-state), for tests:
// {ready, meshes: [{object, triangles, vertices, markers, decode_ms}], pictures: [{caption, width, height}],
//  errors: [...]}; the pictures' sizes are those the browser decoded.
import {
  AmbientLight, BufferAttribute, BufferGeometry, Color, DirectionalLight, DoubleSide, Group, Mesh,
  MeshStandardMaterial, Plane, PerspectiveCamera, Scene, SphereGeometry, MeshBasicMaterial, Vector3, WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import DracoDecoderModule from 'three/examples/jsm/libs/draco/draco_wasm_wrapper.js';
import dracoWasm from 'three/examples/jsm/libs/draco/draco_decoder.wasm';

const state = { ready: false, meshes: [], pictures: [], errors: [] };
window.lacunaPage = state;

function publishState() {
  const el = document.getElementById('lacuna-page-state');
  if (el) el.textContent = JSON.stringify(state);
}

function fail(message) {
  state.errors.push(String(message));
  publishState();
}

// --- small DOM helpers -------------------------------------------------------------------------
function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') node.className = v;
    else if (k === 'text') node.textContent = v;
    else node.setAttribute(k, v);
  }
  for (const c of children) node.append(c instanceof Node ? c : document.createTextNode(String(c)));
  return node;
}

function fmt(x, digits = 4) {
  if (typeof x !== 'number') return x === undefined || x === null ? '' : String(x);
  if (Number.isInteger(x)) return x.toLocaleString('en-US');
  return Number(x.toPrecision(digits)).toLocaleString('en-US', { maximumFractionDigits: 6 });
}

function bytes(n) {
  if (!n) return '0';
  const units = ['B', 'KB', 'MB', 'GB', 'TB'];
  let i = 0;
  while (n >= 1024 && i < units.length - 1) { n /= 1024; ++i; }
  return `${n.toFixed(i ? 1 : 0)} ${units[i]}`;
}

function baseName(path) {
  return String(path).split(/[\\/]/).pop();
}

function table(headers, rows) {
  const t = el('table');
  t.append(el('tr', {}, ...headers.map((h) => el('th', { text: h }))));
  for (const r of rows) t.append(el('tr', {}, ...r.map((c) => (c instanceof Node ? el('td', {}, c) : el('td', { text: c })))));
  return t;
}

function base64Bytes(text) {
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out;
}

// --- Draco ------------------------------------------------------------------------------------
// Decodes on the page's thread (a worker would need a URL, which file:// pages cannot give one).
function decodeDraco(draco, data) {
  const decoder = new draco.Decoder();
  const mesh = new draco.Mesh();
  try {
    const status = decoder.DecodeArrayToMesh(data, data.byteLength, mesh);
    if (!status.ok() || mesh.ptr === 0) throw new Error(`Draco: ${status.error_msg()}`);
    const faces = mesh.num_faces();
    const points = mesh.num_points();
    const indexBytes = faces * 3 * 4;
    const indexPtr = draco._malloc(indexBytes);
    decoder.GetTrianglesUInt32Array(mesh, indexBytes, indexPtr);
    const index = new Uint32Array(draco.HEAPU32.buffer, indexPtr, faces * 3).slice();
    draco._free(indexPtr);
    const attribute = decoder.GetAttribute(mesh, decoder.GetAttributeId(mesh, draco.POSITION));
    const positionBytes = points * 3 * 4;
    const positionPtr = draco._malloc(positionBytes);
    decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, draco.DT_FLOAT32, positionBytes, positionPtr);
    const position = new Float32Array(draco.HEAPF32.buffer, positionPtr, points * 3).slice();
    draco._free(positionPtr);
    return { index, position, faces, points };
  } finally {
    draco.destroy(mesh);
    draco.destroy(decoder);
  }
}

// --- the viewer -------------------------------------------------------------------------------
class Viewer {
  constructor(container, buildDirection) {
    this.container = container;
    this.up = new Vector3(...buildDirection).normalize();
    this.renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.localClippingEnabled = true;
    container.append(this.renderer.domElement);
    this.scene = new Scene();
    this.scene.background = new Color(0xf4f5f7);
    this.camera = new PerspectiveCamera(35, 1, 0.01, 1e6);
    this.camera.up.copy(this.up);
    this.scene.add(new AmbientLight(0xffffff, 0.55));
    this.light = new DirectionalLight(0xffffff, 1.6);
    this.scene.add(this.light);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.section = new Plane(this.up.clone().negate(), 0);
    this.material = new MeshStandardMaterial({ color: 0x8fa9c4, metalness: 0.05, roughness: 0.6, side: DoubleSide,
                                               flatShading: true });
    // Back faces show where the section plane opens the part.
    this.material.onBeforeCompile = (shader) => {
      shader.fragmentShader = shader.fragmentShader.replace(
        '#include <dithering_fragment>',
        '#include <dithering_fragment>\nif (!gl_FrontFacing) gl_FragColor = vec4(0.78, 0.25, 0.2, 1.0);');
    };
    this.markers = new Group();
    this.scene.add(this.markers);
    this.object = null;
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 800;
    const h = this.container.clientHeight || 500;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  show(decoded, markers) {
    if (this.object) {
      this.scene.remove(this.object);
      this.object.geometry.dispose();
    }
    const geometry = new BufferGeometry();
    geometry.setAttribute('position', new BufferAttribute(decoded.position, 3));
    geometry.setIndex(new BufferAttribute(decoded.index, 1));
    geometry.computeBoundingBox();
    this.object = new Mesh(geometry, this.material);
    this.scene.add(this.object);
    this.box = geometry.boundingBox.clone();
    this.markers.clear();
    const size = this.box.getSize(new Vector3()).length();
    const colours = { trapped_voids: 0xd62728, thin_walls: 0xff7f0e, small_holes: 0x9467bd };
    for (const m of markers) {
      const dot = new Mesh(new SphereGeometry(size * 0.012, 12, 8),
                           new MeshBasicMaterial({ color: colours[m.kind] || 0x000000, depthTest: false }));
      dot.position.set(...m.location);
      dot.renderOrder = 1;
      this.markers.add(dot);
    }
    this.setSection(this.sectionOn, this.sectionFraction ?? 0.5);
    this.resetView();
  }

  resetView() {
    if (!this.box) return;
    const centre = this.box.getCenter(new Vector3());
    const radius = this.box.getSize(new Vector3()).length() / 2 || 1;
    // Looking down on the part from an iso direction around the build direction.
    const side = Math.abs(this.up.z) < 0.9 ? new Vector3(0, 0, 1) : new Vector3(1, 0, 0);
    const a = side.clone().sub(this.up.clone().multiplyScalar(side.dot(this.up))).normalize();
    const b = new Vector3().crossVectors(this.up, a);
    const direction = a.multiplyScalar(-1).add(b.multiplyScalar(-1)).add(this.up.clone().multiplyScalar(0.9)).normalize();
    const distance = (radius / Math.sin((this.camera.fov * Math.PI) / 360)) * 0.8;
    this.camera.position.copy(centre).add(direction.multiplyScalar(distance));
    this.camera.near = distance / 1000;
    this.camera.far = distance * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
    this.light.position.copy(this.camera.position).add(this.up.clone().multiplyScalar(radius));
    this.render();
  }

  setWireframe(on) {
    this.material.wireframe = on;
    this.render();
  }

  // The part above the plane at `fraction` of its height along the build direction is cut away.
  setSection(on, fraction) {
    this.sectionOn = on;
    this.sectionFraction = fraction;
    if (this.box) {
      const corners = [];
      for (let i = 0; i < 8; ++i)
        corners.push(new Vector3(i & 1 ? this.box.max.x : this.box.min.x, i & 2 ? this.box.max.y : this.box.min.y,
                                 i & 4 ? this.box.max.z : this.box.min.z).dot(this.up));
      const low = Math.min(...corners), high = Math.max(...corners);
      this.section.constant = low + (high - low) * fraction;
    }
    this.material.clippingPlanes = on ? [this.section] : [];
    this.material.needsUpdate = true;
    this.render();
  }

  setMarkers(on) {
    this.markers.visible = on;
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }
}

// --- the page ---------------------------------------------------------------------------------
function outputRows(report) {
  return report.outputs.map((o) => {
    const checks = o.checks || {};
    const ok = checks.valid === undefined ? '' : checks.valid ? 'pass' : `fail: ${(checks.problems || []).join('; ')}`;
    return [baseName(o.file), o.format, o.object, fmt(o.triangles ?? o.tetrahedra), fmt(o.volume_mm3), fmt(o.surface_area_mm2),
            fmt(o.genus), fmt(o.components), o.relative_density === undefined ? '' : fmt(o.relative_density, 3), ok];
  });
}

function printabilitySection(report) {
  const seen = new Set();
  const rows = [];
  for (const o of report.outputs) {
    if (!o.printability || seen.has(o.object)) continue;
    seen.add(o.object);
    const p = o.printability;
    for (const kind of ['trapped_voids', 'thin_walls', 'small_holes'])
      for (const f of p[kind])
        rows.push([o.object, kind.replace('_', ' '), f.location.map((x) => x.toFixed(3)).join(', '), fmt(f.volume_mm3)]);
    rows.push([o.object, 'overhang area (mm²)', '', fmt(p.overhang_area_mm2)]);
    if (p.drain_holes) rows.push([o.object, 'drain holes drilled', '', p.drain_holes]);
    if (p.thickened_walls) rows.push([o.object, 'walls thickened', '', p.thickened_walls]);
  }
  if (!rows.length) return null;
  return el('section', {}, el('h2', { text: 'Printability' }),
            table(['object', 'finding', 'location (mm)', 'volume (mm³)'], rows));
}

function stagesSection(report) {
  const stages = Object.entries(report.stage_seconds || {}).sort((a, b) => b[1] - a[1]);
  const total = report.total_seconds || 1;
  const rows = stages.map(([name, s]) => {
    const bar = el('div', { class: 'bar' });
    bar.style.width = `${Math.max(0.5, (100 * s) / total)}%`;
    return [name, s.toFixed(3), el('div', { class: 'track' }, bar)];
  });
  return el('section', {}, el('h2', { text: 'Stages' }),
            table(['stage', 'seconds', ''], rows),
            el('p', { text: `total ${fmt(report.total_seconds)} s on ${report.threads} threads; peak memory ` +
                             `${bytes(report.peak_memory_bytes)} (estimate ${bytes(report.memory_estimate_bytes)}, ` +
                             `budget ${bytes(report.memory_budget_bytes)})` }));
}

function inputsSection(report) {
  if (!report.inputs) return null;
  const rows = Object.entries(report.inputs).map(([name, r]) => [name, el('code', { text: JSON.stringify(r) })]);
  return el('section', {}, el('h2', { text: 'Inputs' }), table(['input', 'what building it found'], rows));
}

function picturesSection(page) {
  if (!page.pictures.length) return null;
  const figures = page.pictures.map((p) => {
    const img = el('img', { src: `data:${p.type};base64,${p.data}`, alt: p.caption });
    return el('figure', {}, img, el('figcaption', { text: p.caption }));
  });
  return el('section', {}, el('h2', { text: 'Pictures' }), el('div', { class: 'pictures' }, ...figures));
}

async function main() {
  const report = JSON.parse(document.getElementById('lacuna-report').textContent);
  const page = JSON.parse(document.getElementById('lacuna-page-data').textContent);
  const root = document.getElementById('lacuna');
  document.title = `${report.name}: Lacuna report`;
  root.append(el('h1', { text: report.name }),
              el('p', { class: report.valid ? 'valid' : 'invalid',
                        text: `${report.valid ? 'every output passed its checks' : 'some output failed its checks'} · ` +
                              `recipe ${report.recipe} · Lacuna ${report.lacuna_version} · voxel ` +
                              `${fmt(report.voxel_size_mm)} mm · seed ${report.seed}` }));

  const viewerSection = el('section', {}, el('h2', { text: 'Objects' }));
  root.append(viewerSection);
  root.append(el('section', {}, el('h2', { text: 'Outputs' }),
                 table(['file', 'format', 'object', 'triangles', 'volume (mm³)', 'area (mm²)', 'genus', 'components',
                        'relative density', 'checks'], outputRows(report))));
  for (const s of [printabilitySection(report), stagesSection(report), picturesSection(page), inputsSection(report)])
    if (s) root.append(s);
  // The pictures as the browser decoded them.
  await Promise.all([...root.querySelectorAll('.pictures img')].map(async (img) => {
    await img.decode();
    state.pictures.push({ caption: img.alt, width: img.naturalWidth, height: img.naturalHeight });
  }));
  for (const s of page.skipped || [])
    viewerSection.append(el('p', { text: `${s.object}: ${s.reason}` }));
  if (!page.meshes.length) {
    state.ready = true;
    publishState();
    return;
  }

  const draco = await DracoDecoderModule({ wasmBinary: dracoWasm });
  const decoded = page.meshes.map((m) => {
    const t0 = performance.now();
    const d = decodeDraco(draco, base64Bytes(m.draco));
    state.meshes.push({ object: m.object, triangles: d.faces, vertices: d.points, markers: (m.markers || []).length,
                        decode_ms: Math.round(performance.now() - t0) });
    return d;
  });

  const select = el('select', { id: 'object' }, ...page.meshes.map((m, i) => el('option', { value: i, text: m.object })));
  const wire = el('input', { type: 'checkbox', id: 'wireframe' });
  const section = el('input', { type: 'checkbox', id: 'section' });
  const height = el('input', { type: 'range', id: 'section-height', min: 0, max: 1000, value: 500 });
  const markers = el('input', { type: 'checkbox', id: 'markers', checked: '' });
  const reset = el('button', { id: 'reset', text: 'reset view' });
  const info = el('span', { id: 'mesh-info' });
  viewerSection.append(el('div', { class: 'toolbar' }, select,
                          el('label', {}, wire, 'wireframe'),
                          el('label', {}, section, 'section along the build direction'), height,
                          el('label', {}, markers, 'printability markers'), reset, info));
  const container = el('div', { id: 'viewer' });
  viewerSection.append(container);
  const viewer = new Viewer(container, page.build_direction || [0, 0, 1]);
  const showObject = (i) => {
    const m = page.meshes[i];
    viewer.show(decoded[i], m.markers || []);
    info.textContent = `${fmt(decoded[i].faces)} triangles, ${fmt(decoded[i].points)} vertices ` +
                       `(${m.outputs.map(baseName).join(', ')})`;
  };
  select.addEventListener('change', () => showObject(Number(select.value)));
  wire.addEventListener('change', () => viewer.setWireframe(wire.checked));
  section.addEventListener('change', () => viewer.setSection(section.checked, height.value / 1000));
  height.addEventListener('input', () => { section.checked = true; viewer.setSection(true, height.value / 1000); });
  markers.addEventListener('change', () => viewer.setMarkers(markers.checked));
  reset.addEventListener('click', () => viewer.resetView());
  showObject(0);
  state.ready = true;
  publishState();
}

main().catch((e) => fail(e && e.stack ? e.stack : e));
