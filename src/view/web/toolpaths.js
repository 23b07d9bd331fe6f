// Toolpaths as GPU line buffers: one THREE.LineSegments per group (feature role and tool, or
// the travels of a tool), its segments sorted by layer so a layer range is one draw range.

import * as THREE from 'three';
import { positions, runLengths, varints } from 'conduit/decode';

/** Colours of tools 0, 1, 2… in the "tool" colouring. */
const TOOL_COLOURS = ['#f5a623', '#e600b8', '#4a90e2', '#7ed321', '#9013fe', '#50e3c2'];

/** Builds the line buffers of one job. Returns { groups, layerCount }. */
export function buildToolpaths(job) {
  const layerCount = job.layers.length;
  const groups = job.groups.map((g) => buildGroup(g, layerCount));
  return { groups, layerCount };
}

function buildGroup(g, layerCount) {
  const verts = positions(g.positions, g.vertices);
  const runs = varints(g.runs);
  const feed = runLengths(g.feed, g.segments);
  const width = runLengths(g.width, g.segments);
  const pos = new Float32Array(g.segments * 6);
  const segLayer = new Uint32Array(g.segments);
  // layerStart[l]: first segment of layer l (segments are sorted by layer).
  const layerStart = new Uint32Array(layerCount + 1);
  let v = 0;
  let s = 0;
  for (let r = 0; r + 1 < runs.length; r += 2) {
    const layer = runs[r];
    const n = runs[r + 1];
    for (let k = 0; k + 1 < n; k++) {
      const a = (v + k) * 3;
      const b = (v + k + 1) * 3;
      pos.set(verts.subarray(a, a + 3), s * 6);
      pos.set(verts.subarray(b, b + 3), s * 6 + 3);
      segLayer[s] = layer;
      s++;
    }
    v += n;
  }
  let l = 0;
  for (let i = 0; i < s; i++) {
    while (l <= segLayer[i] && l <= layerCount) layerStart[l++] = i;
  }
  while (l <= layerCount) layerStart[l++] = s;

  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  // Linear colours (three.js works in linear light and encodes the output as sRGB).
  const colour = new Float32Array(s * 6);
  geometry.setAttribute('color', new THREE.BufferAttribute(colour, 3));
  geometry.computeBoundingSphere();
  const material = new THREE.LineBasicMaterial({
    vertexColors: true,
    transparent: g.travel,
    opacity: g.travel ? 0.5 : 1,
  });
  const lines = new THREE.LineSegments(geometry, material);
  lines.frustumCulled = false;
  lines.visible = !g.travel;
  lines.userData = { group: g };
  // Conductive beads are few and are what an electronics job is about: they are also drawn at
  // their true width as flat ribbons, so a trace reads at any zoom, not as a 1 px line.
  const ribbon = /conductive/i.test(g.role) ? buildRibbon(pos, width, s, g.colour) : null;
  if (ribbon) lines.add(ribbon);
  return {
    info: g,
    lines,
    ribbon,
    segments: s,
    segLayer,
    layerStart,
    feed,
    width,
    drawn: 0,
  };
}

/** Two triangles per segment, `width` µm wide (0.4 mm when not given), at the segment's z. */
function buildRibbon(pos, width, count, colour) {
  const tri = new Float32Array(count * 18);
  for (let i = 0; i < count; i++) {
    const [ax, ay, az, bx, by, bz] = pos.subarray(i * 6, i * 6 + 6);
    const len = Math.hypot(bx - ax, by - ay) || 1;
    const half = (width[i] > 0 ? width[i] / 1000 : 0.4) / 2;
    const nx = (-(by - ay) / len) * half;
    const ny = ((bx - ax) / len) * half;
    tri.set([ax + nx, ay + ny, az, ax - nx, ay - ny, az, bx + nx, by + ny, bz,
      bx + nx, by + ny, bz, ax - nx, ay - ny, az, bx - nx, by - ny, bz], i * 18);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(tri, 3));
  const mesh = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ color: colour, side: THREE.DoubleSide }));
  mesh.frustumCulled = false;
  mesh.name = 'ribbon';
  return mesh;
}

/** Sets the drawn layers [from, to] (0-based, inclusive) of every group. */
export function setLayerRange(groups, from, to) {
  for (const g of groups) {
    const a = g.layerStart[Math.min(from, g.layerStart.length - 1)];
    const b = g.layerStart[Math.min(to + 1, g.layerStart.length - 1)];
    g.lines.geometry.setDrawRange(a * 2, Math.max(0, b - a) * 2);
    if (g.ribbon) g.ribbon.geometry.setDrawRange(a * 6, Math.max(0, b - a) * 6);
    g.drawn = Math.max(0, b - a);
  }
}

/** Hex `#rrggbb` to [r, g, b] in 0–255. */
export function rgb(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [(n >> 16) & 255, (n >> 8) & 255, n & 255];
}

/** The colour of tool `t`. */
export function toolColour(t) {
  return TOOL_COLOURS[t % TOOL_COLOURS.length];
}

/** Blue → cyan → green → yellow → red for t in [0, 1]. */
export function ramp(t) {
  const stops = [
    [0x30, 0x60, 0xe0],
    [0x20, 0xc0, 0xe0],
    [0x40, 0xc0, 0x40],
    [0xf0, 0xd0, 0x20],
    [0xe0, 0x30, 0x30],
  ];
  const x = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0)) * (stops.length - 1);
  const i = Math.min(stops.length - 2, Math.floor(x));
  const f = x - i;
  return stops[i].map((c, k) => Math.round(c + (stops[i + 1][k] - c) * f));
}

/**
 * Recolours every group for `mode` ('feature', 'tool', 'speed', 'width', 'time'); `layerTimes`
 * are the job's layer times. Returns the legend's range { min, max, unit } for the ramp modes.
 */
export function colourBy(groups, mode, layerTimes) {
  let range = null;
  if (mode === 'speed' || mode === 'width' || mode === 'time') {
    let min = Infinity;
    let max = -Infinity;
    for (const g of groups) {
      if (g.info.travel) continue;
      for (let i = 0; i < g.segments; i++) {
        const v = value(g, i, mode, layerTimes);
        if (v > 0) {
          min = Math.min(min, v);
          max = Math.max(max, v);
        }
      }
    }
    if (!(min <= max)) {
      min = 0;
      max = 1;
    }
    range = { min, max, unit: { speed: 'mm/s', width: 'mm', time: 's' }[mode] };
  }
  for (const g of groups) {
    const attr = g.lines.geometry.getAttribute('color');
    const c = attr.array;
    const fixed = mode === 'feature' ? rgb(g.info.colour) : mode === 'tool' ? rgb(toolColour(g.info.tool)) : null;
    for (let i = 0; i < g.segments; i++) {
      let col = fixed;
      if (!col) {
        if (g.info.travel) {
          col = [0x99, 0x99, 0x99];
        } else {
          const v = value(g, i, mode, layerTimes);
          col = v > 0 ? ramp((v - range.min) / (range.max - range.min || 1)) : [0x80, 0x80, 0x80];
        }
      }
      const lin = linear(col);
      c.set(lin, i * 6);
      c.set(lin, i * 6 + 3);
    }
    attr.needsUpdate = true;
    if (g.ribbon) {
      // The ribbons carry the feature or tool colour; in the ramp modes the lines alone do.
      g.ribbon.visible = mode === 'feature' || mode === 'tool';
      g.ribbon.material.color.set(mode === 'tool' ? toolColour(g.info.tool) : g.info.colour);
    }
  }
  return range;
}

const linearCache = new Map();

/** An sRGB colour [r, g, b] (0–255) in three.js's linear working space, [r, g, b] in 0–1. */
function linear(col) {
  const key = (col[0] << 16) | (col[1] << 8) | col[2];
  let v = linearCache.get(key);
  if (!v) {
    const c = new THREE.Color().setRGB(col[0] / 255, col[1] / 255, col[2] / 255, THREE.SRGBColorSpace);
    v = [c.r, c.g, c.b];
    linearCache.set(key, v);
  }
  return v;
}

function value(g, i, mode, layerTimes) {
  if (mode === 'speed') return g.feed[i] / 10;
  if (mode === 'width') return g.width[i] / 1000;
  return layerTimes[g.segLayer[i]] || 0;
}
