// The studio: the view plus placing parts by hand against `conduit studio`'s local server.
// Drag a part on its seating plane, type its x, y, z and rotation, see the checks' flags and
// the rubberbands follow, Route (the same walk as `conduit slice --circuit`), Save the TOML.

import * as THREE from 'three';
import 'conduit/main';
import { el } from 'conduit/panel';

const view = window.conduitView;
const studio = view.data.studio;
const status = el('div', { id: 'studio-status', class: 'status' });
const problems = el('ul', { id: 'studio-problems', class: 'problems' });
const rows = el('div', { id: 'studio-parts', class: 'parts' });
let pending = null; // the latest poses waiting to be sent
let sending = false;
// The poses the drawn circuit was made from: a part moved since is drawn offset until the
// server's answer for its new pose arrives.
let drawnPoses = Object.fromEntries(studio.parts.map((p) => [p.name, { x: p.x, y: p.y }]));

function offsetGroups() {
  for (const group of view.circuitParts.children) {
    const name = group.userData.part.name;
    const part = studio.parts.find((p) => p.name === name);
    const drawn = drawnPoses[name];
    if (part && drawn) group.position.set(part.x - drawn.x, part.y - drawn.y, 0);
  }
}

/** POST `body` as JSON to `path`; the parsed answer, or an Error with the server's message. */
async function post(path, body) {
  const r = await fetch(path, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(body),
  });
  const answer = await r.json().catch(() => ({ error: `${r.status} ${r.statusText}` }));
  if (!r.ok) throw new Error(answer.error || `${r.status}`);
  return answer;
}

function poses() {
  return studio.parts.map((p) => ({ name: p.name, x: p.x, y: p.y, z: p.z, rotation: p.rotation }));
}

/** Sends the poses; while a request is out, only the latest change waits. */
async function sendPoses() {
  pending = poses();
  if (sending) return;
  sending = true;
  try {
    while (pending) {
      const body = { parts: pending };
      pending = null;
      const answer = await post('api/place', body);
      drawnPoses = Object.fromEntries(body.parts.map((p) => [p.name, { x: p.x, y: p.y }]));
      showChecks(answer);
    }
  } catch (e) {
    status.textContent = `error: ${e.message}`;
  } finally {
    sending = false;
  }
}

function showChecks(answer) {
  studio.flagged = answer.flagged;
  studio.problems = answer.problems;
  studio.notes = answer.notes;
  view.setCircuit(answer.circuit, answer.flagged);
  problems.replaceChildren(...answer.problems.map((p) => el('li', {}, p)));
  for (const row of rows.children) row.classList.toggle('flagged', answer.flagged.includes(row.dataset.part));
  window.conduitStudio.checks += 1;
  offsetGroups();
  view.render();
}

function numberInput(part, key, step) {
  return el('input', {
    type: 'number', step, value: part[key].toFixed(key === 'rotation' ? 1 : 3),
    'data-part': part.name, 'data-key': key, class: `pose-${key}`,
    onchange: (e) => {
      const v = Number(e.target.value);
      if (!Number.isFinite(v)) return;
      part[key] = v;
      sendPoses();
    },
  });
}

function buildRows() {
  rows.replaceChildren(...studio.parts.map((p) => el('div', { class: 'part-row', 'data-part': p.name },
    el('span', { class: 'part-name' }, `${p.name} (${p.method})`),
    el('label', {}, 'x ', numberInput(p, 'x', 0.5)),
    el('label', {}, 'y ', numberInput(p, 'y', 0.5)),
    el('label', {}, 'z ', numberInput(p, 'z', 0.2)),
    el('label', {}, 'rot ', numberInput(p, 'rotation', 90)))));
  for (const row of rows.children) row.classList.toggle('flagged', studio.flagged.includes(row.dataset.part));
}

function refreshInputs(part) {
  for (const input of rows.querySelectorAll(`input[data-part="${CSS.escape(part.name)}"]`)) {
    const key = input.dataset.key;
    input.value = part[key].toFixed(key === 'rotation' ? 1 : 3);
  }
}

async function route() {
  status.textContent = 'routing…';
  const poll = setInterval(async () => {
    try {
      const p = await (await fetch('api/progress')).json();
      if (p.running) status.textContent = `routing: ${p.done} of ${p.total} wires searched, round ${p.round}, ${p.unrouted} unrouted`;
    } catch (e) {
      // The next poll tries again.
    }
  }, 300);
  try {
    const body = { parts: poses() };
    const answer = await post('api/route', body);
    view.addJob(answer.job);
    // Up to the top of the traces, so the circuit is not hidden under the layers above it.
    const traces = view.layersOf('Conductive trace');
    if (traces) view.setLayers(1, traces[1] + 1);
    drawnPoses = Object.fromEntries(body.parts.map((p) => [p.name, { x: p.x, y: p.y }]));
    view.setCircuit(answer.circuit, studio.flagged);
    offsetGroups();
    status.textContent = answer.summary;
    window.conduitStudio.routes += 1;
  } catch (e) {
    status.textContent = `route failed: ${e.message}`;
  } finally {
    clearInterval(poll);
  }
}

async function export3de() {
  try {
    const answer = await post('api/export-3de', { parts: poses() });
    status.textContent = `exported ${answer.path}`;
    window.conduitStudio.exports += 1;
  } catch (e) {
    status.textContent = `export failed: ${e.message}`;
  }
}

async function save() {
  try {
    const answer = await post('api/save', { parts: poses() });
    status.textContent = `saved ${answer.path}`;
    window.conduitStudio.saves += 1;
  } catch (e) {
    status.textContent = `save failed: ${e.message}`;
  }
}

// ---- dragging on the seating plane ---------------------------------------------------------

const raycaster = new THREE.Raycaster();
let drag = null; // { part (pose), group, plane, start: Vector3, x0, y0 }

function pointer(e) {
  const rect = view.canvas.getBoundingClientRect();
  return new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
}

function onPlane(e, z) {
  raycaster.setFromCamera(pointer(e), view.camera);
  const hit = new THREE.Vector3();
  return raycaster.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), -z), hit) ? hit : null;
}

function inside(outline, x, y) {
  let c = false;
  for (let i = 0, j = outline.length - 1; i < outline.length; j = i++) {
    const [xi, yi] = outline[i];
    const [xj, yj] = outline[j];
    if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) c = !c;
  }
  return c;
}

view.canvas.addEventListener('pointerdown', (e) => {
  if (e.button !== 0) return;
  // Parts whose footprint is under the pointer on their own seating plane; the nearest wins.
  let best = null;
  for (const group of view.circuitParts.children) {
    const drawn = group.userData.part;
    const hit = onPlane(e, drawn.z);
    if (!hit || !inside(drawn.outline, hit.x, hit.y)) continue;
    const d = hit.distanceTo(view.camera.position);
    if (!best || d < best.d) best = { group, drawn, hit, d };
  }
  if (!best) return;
  const part = studio.parts.find((p) => p.name === best.drawn.name);
  if (!part) return;
  drag = { part, z: best.drawn.z, start: best.hit, x0: part.x, y0: part.y };
  view.controls.enabled = false;
  view.canvas.setPointerCapture(e.pointerId);
  e.preventDefault();
});

view.canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const hit = onPlane(e, drag.z);
  if (!hit) return;
  const dx = hit.x - drag.start.x;
  const dy = hit.y - drag.start.y;
  drag.part.x = drag.x0 + dx;
  drag.part.y = drag.y0 + dy;
  offsetGroups();
  refreshInputs(drag.part);
  view.render();
  sendPoses();
});

function endDrag(e) {
  if (!drag) return;
  view.canvas.releasePointerCapture(e.pointerId);
  drag = null;
  view.controls.enabled = true;
  sendPoses();
}
view.canvas.addEventListener('pointerup', endDrag);
view.canvas.addEventListener('pointercancel', endDrag);

// ---- panel -----------------------------------------------------------------------------------

buildRows();
problems.replaceChildren(...studio.problems.map((p) => el('li', {}, p)));
view.addSection(el('section', { id: 'studio' },
  el('h2', {}, 'Parts'),
  el('div', { class: 'buttons' },
    el('button', { id: 'route', onclick: route }, 'Route'),
    el('button', { id: 'save', onclick: save }, 'Save'),
    el('button', { id: 'export-3de', onclick: export3de }, 'Export .3de')),
  status,
  el('div', { class: 'hint', title: studio.save_path },
    `Drag a part on its plane, or type its pose (${studio.origin} frame). Save writes ${studio.save_path.split(/[\\/]/).pop()}.`),
  rows,
  problems));

window.conduitStudio = {
  /** Poses as the page holds them. */
  parts: () => poses(),
  /** Answers from the checks, routes and saves so far. */
  checks: 0,
  routes: 0,
  saves: 0,
  exports: 0,
  flagged: () => studio.flagged.slice(),
  status: () => status.textContent,
};
document.body.dataset.ready = 'true';
