// Everything drawn besides toolpaths: the model mesh, retraction and z-hop markers, parts as
// labelled boxes at their seating plane, cavity outlines, rubberbands of unrouted wires.

import * as THREE from 'three';
import { deltaIndices, positions, varints } from 'conduit/decode';

/** Colour of trace-related overlays: parts, pads. */
export const PART_COLOUR = 0xffffff;
/** Colour of rubberbands of unrouted wires. */
export const RUBBERBAND_COLOUR = 0xff2020;
/** Colour of parts flagged (outside the solid, overlapping). */
export const FLAGGED_COLOUR = 0xff8000;

/** The model's meshes, half transparent. */
export function buildMeshes(models) {
  const group = new THREE.Group();
  for (const m of models) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions(m.positions, m.vertices), 3));
    geometry.setIndex(new THREE.BufferAttribute(deltaIndices(m.indices, m.triangles * 3), 1));
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial({
      color: 0x9ab0c8,
      transparent: true,
      opacity: 0.25,
      depthWrite: false,
      side: THREE.DoubleSide,
    });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.name = m.name;
    group.add(mesh);
  }
  return group;
}

/** Point markers with a per-point layer, sorted by layer; returns { points, layerStart }. */
export function buildMarkers(markers, layerCount, colour, size) {
  const pos = positions(markers.positions, markers.count);
  const layers = varints(markers.layers);
  const order = [...Array(markers.count).keys()].sort((a, b) => layers[a] - layers[b] || a - b);
  const sorted = new Float32Array(markers.count * 3);
  order.forEach((src, dst) => sorted.set(pos.subarray(src * 3, src * 3 + 3), dst * 3));
  const layerStart = new Uint32Array(layerCount + 1);
  let l = 0;
  order.forEach((src, i) => {
    while (l <= layers[src] && l <= layerCount) layerStart[l++] = i;
  });
  while (l <= layerCount) layerStart[l++] = markers.count;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(sorted, 3));
  const points = new THREE.Points(
    geometry,
    new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: false }),
  );
  points.frustumCulled = false;
  points.visible = false;
  return { points, layerStart };
}

/** Shows markers of layers [from, to]. */
export function setMarkerRange(m, from, to) {
  const a = m.layerStart[Math.min(from, m.layerStart.length - 1)];
  const b = m.layerStart[Math.min(to + 1, m.layerStart.length - 1)];
  m.points.geometry.setDrawRange(a, Math.max(0, b - a));
}

/** A closed outline at height z as line-segment pairs appended to `out`. */
function loop(out, outline, z) {
  for (let i = 0; i < outline.length; i++) {
    const a = outline[i];
    const b = outline[(i + 1) % outline.length];
    out.push(a[0], a[1], z, b[0], b[1], z);
  }
}

/** A prism's edges: the outline at z and z + h, and the vertical edges. */
export function prismSegments(outline, z, h) {
  const out = [];
  loop(out, outline, z);
  if (h > 0) {
    loop(out, outline, z + h);
    for (const p of outline) out.push(p[0], p[1], z, p[0], p[1], z + h);
  }
  return out;
}

function segments(array, colour, dashed) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(array, 3));
  const material = dashed
    ? new THREE.LineDashedMaterial({ color: colour, dashSize: 0.4, gapSize: 0.3 })
    : new THREE.LineBasicMaterial({ color: colour });
  const lines = new THREE.LineSegments(geometry, material);
  if (dashed) lines.computeLineDistances();
  lines.frustumCulled = false;
  return lines;
}

/**
 * One part: its box (footprint prism), pads and cavity outline. `parts` entries come from the
 * circuit (with pads and cavity) or from the file's OctoPNP block (outline only).
 */
export function buildPart(part) {
  const group = new THREE.Group();
  group.name = part.name;
  const box = segments(prismSegments(part.outline, part.z, Math.max(part.height, 0.05)), PART_COLOUR);
  box.name = 'box';
  group.add(box);
  if (part.cavity) {
    const cav = [];
    for (const c of part.cavity) loop(cav, c, part.z + 0.01);
    const cavity = segments(cav, 0xffd000, true);
    cavity.name = 'cavity';
    group.add(cavity);
  }
  if (part.pads && part.pads.length) {
    const pads = [];
    for (const p of part.pads) loop(pads, p.outline, part.z + 0.02);
    const padLines = segments(pads, 0xd8a040);
    padLines.name = 'pads';
    group.add(padLines);
  }
  group.userData = { part };
  return group;
}

/** The centre of an outline, for labels. */
export function centre(outline) {
  let x = 0;
  let y = 0;
  for (const p of outline) {
    x += p[0];
    y += p[1];
  }
  const n = Math.max(1, outline.length);
  return [x / n, y / n];
}

/** Rubberbands of unrouted wires: red lines drawn over everything. */
export function buildRubberbands(unrouted) {
  const array = [];
  for (const w of unrouted) array.push(...w.from, ...w.to);
  const lines = segments(array, RUBBERBAND_COLOUR);
  lines.material.depthTest = false;
  lines.renderOrder = 10;
  lines.name = 'rubberbands';
  return lines;
}
