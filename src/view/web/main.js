// The 3D view's entry: reads the embedded job data, builds the scene, wires the controls and
// exposes `window.conduitView` (the page's state, for people in the console and for tests).

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls';
import { buildToolpaths, colourBy, ramp, rgb, setLayerRange, toolColour } from 'conduit/toolpaths';
import { FLAGGED_COLOUR, buildMarkers, buildMeshes, buildPart, buildRubberbands, centre, setMarkerRange } from 'conduit/overlays';
import { el, featureLegend, figures, list, rampLegend, section } from 'conduit/panel';

const data = JSON.parse(document.getElementById('conduit-data').textContent);
const view = document.getElementById('view');
const panel = document.getElementById('panel');
const labels = document.getElementById('labels');

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x262a31);
view.prepend(renderer.domElement);
const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 1.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(1, -1, 2);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(35, 1, 0.1, 10000);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, renderer.domElement);
controls.screenSpacePanning = true;

// Overlays shared by every job: model and circuit.
const models = buildMeshes(data.models || []);
scene.add(models);
const circuitParts = new THREE.Group();
scene.add(circuitParts);
let rubberbands = null;

/** Draws `circuit` (parts, cavities, unrouted wires), replacing what was drawn; `flagged` names
 * parts to draw in the warning colour. */
function setCircuit(circuit, flagged = []) {
  data.circuit = circuit;
  for (const c of [...circuitParts.children]) {
    circuitParts.remove(c);
    c.traverse((o) => o.geometry && o.geometry.dispose());
  }
  if (rubberbands) {
    scene.remove(rubberbands);
    rubberbands.geometry.dispose();
    rubberbands = null;
  }
  if (!circuit) return;
  for (const p of circuit.parts) {
    const part = buildPart(p);
    if (flagged.includes(p.name)) {
      const box = part.getObjectByName('box');
      if (box) box.material.color.setHex(FLAGGED_COLOUR);
      part.userData.flagged = true;
    }
    circuitParts.add(part);
  }
  rubberbands = buildRubberbands(circuit.unrouted);
  scene.add(rubberbands);
  if (current) applyToggles();
}

/** A job with nothing in it: the studio before its first route. */
function emptyJob() {
  const none = { count: 0, positions: '', layers: '' };
  return {
    name: 'not routed yet', layers: [{ z: 0, time: 0 }], groups: [], retractions: none, zhops: none,
    events: [], parts: [], warnings: [], bounds: [0, 0, 0, 0, 0, 0],
    figures: { lines: 0, layers: 0, time_s: 0, tools: [], print_mm: 0, travel_mm: 0, retractions: 0, tool_changes: 0, errors: 0, warnings: 0 },
  };
}
if (!data.jobs.length) data.jobs.push(emptyJob());

const state = {
  job: 0,
  from: 0,
  to: 0,
  single: false,
  mode: 'feature',
  toggles: { travel: false, retractions: false, zhops: false, model: true, parts: true, grid: true },
};
let current = null; // { job, groups, layerCount, retractions, zhops, parts, grid, bounds }
setCircuit(data.circuit, data.studio ? data.studio.flagged : []);

function boundsOf(job) {
  let b = job.bounds;
  if (b.every((v) => v === 0)) {
    const box = new THREE.Box3().setFromObject(models);
    b = box.isEmpty() ? [-10, -10, 0, 10, 10, 10] : [...box.min.toArray(), ...box.max.toArray()];
  }
  return b;
}

/** Shows `job` (replacing the empty one, else added), e.g. after the studio's Route. */
function addJob(job) {
  if (data.jobs.length === 1 && data.jobs[0].groups.length === 0) data.jobs[0] = job;
  else data.jobs.push(job);
  loadJob(data.jobs.length - 1, false);
}

/** Extra panel sections (the studio's), kept when the panel is rebuilt. */
const extraSections = [];

function loadJob(index, reframe = true) {
  if (current) {
    for (const g of current.groups) scene.remove(g.lines);
    scene.remove(current.retractions.points, current.zhops.points, current.parts, current.grid);
  }
  const job = data.jobs[index];
  const { groups, layerCount } = buildToolpaths(job);
  for (const g of groups) scene.add(g.lines);
  // A file that never extrudes (a CNC program) is all travel: show it.
  if (groups.length && groups.every((g) => g.info.travel)) state.toggles.travel = true;
  const retractions = buildMarkers(job.retractions, layerCount, 0xff40ff, 5);
  const zhops = buildMarkers(job.zhops, layerCount, 0x40ffff, 5);
  scene.add(retractions.points, zhops.points);
  // Parts from the file's OctoPNP block, when no circuit is given.
  const parts = new THREE.Group();
  if (!data.circuit) {
    for (const p of job.parts) parts.add(buildPart(p));
  }
  scene.add(parts);
  const b = boundsOf(job);
  // A grid of at most ~80 lines a side, its step a power of ten (1 mm for a desktop print).
  const size = Math.min(Math.max(b[3] - b[0], b[4] - b[1], 10), 1e12);
  const step = 10 ** Math.max(0, Math.ceil(Math.log10(size / 50)));
  const divisions = Math.ceil((size * 1.6) / step);
  const grid = new THREE.GridHelper(divisions * step, divisions, 0x50565f, 0x3a3f47);
  grid.rotation.x = Math.PI / 2;
  grid.position.set((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, Math.min(0, b[2]) - 0.01);
  scene.add(grid);
  current = { job, groups, layerCount, retractions, zhops, parts, grid, bounds: b };
  state.job = index;
  state.from = 0;
  state.to = Math.max(0, layerCount - 1);
  buildPanel();
  applyToggles();
  applyColour();
  applyLayers();
  if (reframe) setView('iso');
  else render();
}

// ---- panel ---------------------------------------------------------------------------------

const ui = {};

function buildPanel() {
  const job = current.job;
  const n = current.layerCount;
  panel.replaceChildren();
  panel.append(el('h1', {}, data.studio ? 'conduit studio' : 'conduit view'));
  for (const s of extraSections) panel.append(s);
  if (data.jobs.length > 1) {
    const select = el('select', { id: 'job', onchange: (e) => loadJob(Number(e.target.value)) },
      ...data.jobs.map((j, i) => el('option', { value: i, selected: i === state.job }, j.name)));
    panel.append(select);
  } else {
    panel.append(el('div', { class: 'file', id: 'job-name' }, job.name));
  }
  ui.layerLabel = el('div', { id: 'layer-label', class: 'layer-label' });
  ui.from = el('input', { type: 'range', id: 'layer-from', min: 1, max: Math.max(1, n), value: 1, oninput: (e) => {
    state.from = Number(e.target.value) - 1;
    if (state.single) state.to = state.from;
    if (state.from > state.to) state.to = state.from;
    applyLayers();
  } });
  ui.to = el('input', { type: 'range', id: 'layer-to', min: 1, max: Math.max(1, n), value: Math.max(1, n), oninput: (e) => {
    state.to = Number(e.target.value) - 1;
    if (state.single) state.from = state.to;
    if (state.to < state.from) state.from = state.to;
    applyLayers();
  } });
  ui.single = el('input', { type: 'checkbox', id: 'single-layer', onchange: (e) => {
    state.single = e.target.checked;
    if (state.single) state.from = state.to;
    applyLayers();
  } });
  panel.append(section('Layers', el('div', { class: 'layers' },
    ui.layerLabel,
    el('label', {}, 'from ', ui.from),
    el('label', {}, 'to ', ui.to),
    el('label', {}, ui.single, ' single layer'),
  ), 'layers'));

  ui.mode = el('select', { id: 'colour-by', onchange: (e) => { state.mode = e.target.value; applyColour(); } },
    ...[['feature', 'feature type'], ['tool', 'tool'], ['speed', 'speed'], ['width', 'width'], ['time', 'layer time']]
      .map(([v, t]) => el('option', { value: v, selected: v === state.mode }, t)));
  ui.legend = el('div', { id: 'legend-box' });
  panel.append(section('Colour by', el('div', {}, ui.mode, ui.legend), 'colour'));

  const toggle = (key, text) => el('label', { class: 'toggle' }, el('input', {
    type: 'checkbox', id: `show-${key}`, checked: state.toggles[key],
    onchange: (e) => { state.toggles[key] = e.target.checked; applyToggles(); },
  }), ` ${text}`);
  panel.append(section('Show', el('div', { class: 'toggles' },
    toggle('travel', 'travel moves'),
    toggle('retractions', `retractions (${job.retractions.count})`),
    toggle('zhops', `z-hops (${job.zhops.count})`),
    data.models && data.models.length ? toggle('model', 'model') : null,
    toggle('parts', 'parts'),
    toggle('grid', 'grid'),
  ), 'show'));
  panel.append(section('View', el('div', { class: 'buttons' },
    ...['top', 'front', 'iso', 'fit'].map((v) => el('button', { id: `view-${v}`, onclick: () => setView(v) }, v))), 'view-presets'));

  panel.append(section('Figures', figures(job), 'figures-section'));
  const events = job.events.map((e) => el('a', { href: '#', onclick: (ev) => { ev.preventDefault(); showLayer(e.layer); } },
    `${e.machine ? 'pick and place' : 'insert by hand'} ${e.part} — layer ${e.layer + 1} (line ${e.line})`));
  panel.append(section('Part events', list(events, 'events'), 'events'));
  if (data.circuit) {
    const c = data.circuit;
    const wires = c.unrouted.map((w) => `${w.net}: ${w.pins[0]} – ${w.pins[1]}`);
    panel.append(section('Circuit', el('div', {},
      el('div', { id: 'circuit-summary' }, `${c.parts.length} parts, ${c.wires - c.unrouted.length} of ${c.wires} wires connected`),
      list(wires, 'unrouted'),
      list(c.problems, 'problems')), 'circuit'));
  }
  panel.append(section('Warnings', list(job.warnings, 'warnings'), 'warnings'));
}

function showLayer(layer) {
  state.single = true;
  ui.single.checked = true;
  state.from = state.to = layer;
  applyLayers();
}

function applyLayers() {
  const { groups, layerCount, job } = current;
  state.from = Math.max(0, Math.min(state.from, layerCount - 1));
  state.to = Math.max(state.from, Math.min(state.to, layerCount - 1));
  setLayerRange(groups, state.from, state.to);
  setMarkerRange(current.retractions, state.from, state.to);
  setMarkerRange(current.zhops, state.from, state.to);
  ui.from.value = state.from + 1;
  ui.to.value = state.to + 1;
  const z = (l) => (job.layers[l] ? job.layers[l].z.toFixed(3) : '–');
  ui.layerLabel.textContent = state.from === state.to
    ? `layer ${state.to + 1} of ${layerCount} · z ${z(state.to)} mm`
    : `layers ${state.from + 1}–${state.to + 1} of ${layerCount} · z ${z(state.from)}–${z(state.to)} mm`;
  // Parts show from the layer they are placed in.
  const top = job.groups.length && job.layers[state.to] ? job.layers[state.to].z : Infinity;
  for (const p of [...circuitParts.children, ...current.parts.children]) {
    p.visible = state.toggles.parts && p.userData.part.z <= top + 1e-6;
  }
  render();
}

function applyToggles() {
  const t = state.toggles;
  current.groups.forEach((g, i) => {
    if (g.info.travel) g.lines.visible = t.travel;
    const box = panel.querySelector(`input[data-group="${i}"]`);
    if (box) box.checked = g.lines.visible;
  });
  current.retractions.points.visible = t.retractions;
  current.zhops.points.visible = t.zhops;
  models.visible = t.model;
  current.grid.visible = t.grid;
  if (rubberbands) rubberbands.visible = t.parts;
  applyLayers();
}

function applyColour() {
  const layerTimes = current.job.layers.map((l) => l.time);
  const range = colourBy(current.groups, state.mode, layerTimes);
  if (state.mode === 'feature') {
    ui.legend.replaceChildren(featureLegend(current.groups, (i, on) => {
      current.groups[i].lines.visible = on;
      if (current.groups[i].info.travel) {
        state.toggles.travel = on;
        const box = document.getElementById('show-travel');
        if (box) box.checked = on;
      }
      render();
    }));
  } else if (state.mode === 'tool') {
    const tools = [...new Set(current.groups.filter((g) => !g.info.travel).map((g) => g.info.tool))].sort((a, b) => a - b);
    ui.legend.replaceChildren(el('div', { class: 'legend', id: 'legend' }, ...tools.map((t) =>
      el('div', { class: 'legend-row' }, el('span', { class: 'swatch', style: `background:${toolColour(t)}` }), `tool ${t}`))));
  } else {
    const title = { speed: 'feed rate', width: 'extrusion width', time: 'layer time' }[state.mode];
    ui.legend.replaceChildren(rampLegend(range, [0, 0.25, 0.5, 0.75, 1].map(ramp), title));
  }
  render();
}

// ---- camera ----------------------------------------------------------------------------------

function setView(name) {
  const b = current.bounds;
  const c = new THREE.Vector3((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
  const r = Math.max(0.5 * Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]), 1);
  const d = (r / Math.sin((camera.fov * Math.PI) / 360)) * 1.1;
  const dir = {
    top: new THREE.Vector3(0, -0.0001, 1),
    front: new THREE.Vector3(0, -1, 0),
    iso: new THREE.Vector3(-1, -1.4, 1.1),
    fit: camera.position.clone().sub(controls.target),
  }[name] || new THREE.Vector3(-1, -1.4, 1.1);
  dir.normalize();
  controls.target.copy(c);
  camera.position.copy(c).addScaledVector(dir, d);
  camera.near = d / 1000;
  camera.far = d * 20;
  camera.updateProjectionMatrix();
  controls.update();
  render();
}

// ---- rendering -------------------------------------------------------------------------------

let frames = 0;
function resize() {
  const w = view.clientWidth;
  const h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}

function project(p) {
  const v = new THREE.Vector3(p[0], p[1], p[2]).project(camera);
  const rect = renderer.domElement.getBoundingClientRect();
  return [rect.left + ((v.x + 1) / 2) * rect.width, rect.top + ((1 - v.y) / 2) * rect.height, v.z];
}

function updateLabels() {
  const items = [];
  for (const p of [...circuitParts.children, ...(current ? current.parts.children : [])]) {
    if (!p.visible) continue;
    const part = p.userData.part;
    const [x, y] = centre(part.outline);
    const [sx, sy, sz] = project([x, y, part.z + part.height]);
    if (sz > 1) continue;
    const rect = view.getBoundingClientRect();
    items.push(el('div', { class: p.userData.flagged ? 'label flagged' : 'label', 'data-part': part.name, style: `left:${sx - rect.left}px;top:${sy - rect.top}px` }, part.name));
  }
  labels.replaceChildren(...items);
}

function render() {
  if (!current) return;
  renderer.render(scene, camera);
  updateLabels();
  if (frames === 0) document.body.dataset.firstFrameMs = performance.now().toFixed(0);
  frames++;
}

controls.addEventListener('change', render);
window.addEventListener('resize', () => { resize(); render(); });
window.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement && e.target.type !== 'range') return;
  if (e.key === 'ArrowUp' || e.key === 'ArrowDown') {
    const d = e.key === 'ArrowUp' ? 1 : -1;
    state.to = Math.max(0, Math.min(current.layerCount - 1, state.to + d));
    if (state.single) state.from = state.to;
    applyLayers();
    e.preventDefault();
  }
});

/** The layers (0-based) holding segments of `role`: [first, last], or null. */
function layersOf(role) {
  let first = Infinity;
  let last = -1;
  for (const g of current.groups) {
    if (g.info.role !== role || g.segments === 0) continue;
    first = Math.min(first, g.segLayer[0]);
    last = Math.max(last, g.segLayer[g.segments - 1]);
  }
  return last < 0 ? null : [first, last];
}

/**
 * Settings from the address's fragment, so a view can be shared as a link:
 * `#layers=1-20&view=top&colour=speed&show=travel,retractions&hide=model`.
 */
function applyHash() {
  const params = new URLSearchParams(window.location.hash.slice(1));
  const layers = params.get('layers');
  if (layers) {
    const [a, b] = layers.split('-').map(Number);
    if (Number.isFinite(a)) {
      state.from = a - 1;
      state.to = Number.isFinite(b) ? b - 1 : a - 1;
      state.single = !Number.isFinite(b);
      ui.single.checked = state.single;
    }
  }
  for (const [key, on] of [['show', true], ['hide', false]]) {
    for (const t of (params.get(key) || '').split(',')) {
      if (t in state.toggles) {
        state.toggles[t] = on;
        const box = document.getElementById(`show-${t}`);
        if (box) box.checked = on;
      }
    }
  }
  const colour = params.get('colour');
  if (['feature', 'tool', 'speed', 'width', 'time'].includes(colour)) {
    state.mode = colour;
    ui.mode.value = colour;
  }
  applyToggles();
  applyColour();
  const preset = params.get('view');
  if (['top', 'front', 'iso'].includes(preset)) setView(preset);
}

resize();
loadJob(0);
applyHash();

window.conduitView = {
  /** True once the first frame is drawn. */
  ready: true,
  /** Frames drawn so far. */
  frames: () => frames,
  /** The page's state: job, layer range, colouring, segments drawn. */
  state: () => ({
    job: state.job,
    from: state.from,
    to: state.to,
    single: state.single,
    mode: state.mode,
    layerCount: current.layerCount,
    drawnSegments: current.groups.filter((g) => g.lines.visible).reduce((n, g) => n + g.drawn, 0),
    groups: current.groups.map((g) => ({ role: g.info.role, tool: g.info.tool, visible: g.lines.visible, drawn: g.drawn, segments: g.segments })),
    labels: [...labels.children].map((l) => l.textContent),
  }),
  /** Shows layers from–to (1-based, inclusive). */
  setLayers: (from, to) => { state.single = false; ui.single.checked = false; state.from = from - 1; state.to = to - 1; applyLayers(); },
  /** Shows one layer (1-based). */
  showLayer: (layer) => showLayer(layer - 1),
  setView,
  /** Screen position (CSS px in the window) and depth of a point, mm. */
  project,
  render,
  scene,
  camera,
  controls,
  canvas: renderer.domElement,
  circuitParts,
  data,
  setCircuit,
  addJob,
  layersOf,
  /** Adds a panel section shown above the others. */
  addSection: (section) => { extraSections.push(section); buildPanel(); applyColour(); applyLayers(); },
};
// The studio's module says when it is ready.
if (!data.studio) document.body.dataset.ready = 'true';
