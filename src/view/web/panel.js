// The side panel: figures of the job, the legend, part events, circuit problems, warnings.
// Plain DOM, no framework; every function returns or fills an element.

/** `el('div', {class: 'x'}, child, 'text')`. */
export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (v !== false && v !== null && v !== undefined) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) {
    if (c === null || c === undefined) continue;
    e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return e;
}

/** `1h 2m 3s`, `17m 0s`, `42s`, as `conduit check` prints durations. */
export function duration(seconds) {
  const s = Math.max(0, Math.round(seconds));
  const h = Math.floor(s / 3600);
  const m = Math.floor(s / 60) % 60;
  const r = s % 60;
  if (h > 0) return `${h}h ${m}m ${r}s`;
  if (m > 0) return `${m}m ${r}s`;
  return `${r}s`;
}

/** The figures table of a job. */
export function figures(job) {
  const f = job.figures;
  const rows = [
    ['Layers', f.layers],
    ['Estimated time', duration(f.time_s)],
    ...f.tools.map((t) => [`Tool ${t.tool}`, `${t.filament_mm.toFixed(1)} mm (${(t.filament_mm3 / 1000).toFixed(2)} cm³)`]),
    ['Extrusion path', `${(f.print_mm / 1000).toFixed(2)} m`],
    ['Travel path', `${(f.travel_mm / 1000).toFixed(2)} m`],
    ['Retractions', f.retractions],
    ['Tool changes', f.tool_changes],
    ['Check', `${f.errors} error(s), ${f.warnings} warning(s)`],
  ];
  return el(
    'table',
    { class: 'figures', id: 'figures' },
    ...rows.map(([k, v]) => el('tr', {}, el('th', {}, k), el('td', {}, v))),
  );
}

/** The legend of the feature colouring: one row per group with a visibility toggle. */
export function featureLegend(groups, onToggle) {
  return el(
    'div',
    { class: 'legend', id: 'legend' },
    ...groups.map((g, i) =>
      el(
        'label',
        { class: 'legend-row', 'data-role': g.info.role, 'data-tool': g.info.tool },
        el('input', {
          type: 'checkbox',
          checked: g.lines.visible,
          'data-group': i,
          onchange: (e) => onToggle(i, e.target.checked),
        }),
        el('span', { class: 'swatch', style: `background:${g.info.colour}` }),
        `${g.info.role} (T${g.info.tool})`,
        el('span', { class: 'count' }, g.segments.toLocaleString('en')),
      ),
    ),
  );
}

/** A ramp legend: gradient bar with its min and max. */
export function rampLegend(range, colours, title) {
  const stops = colours.map((c, i) => `rgb(${c.join(',')}) ${(100 * i) / (colours.length - 1)}%`).join(',');
  const fmt = (v) => (Math.abs(v) >= 100 ? v.toFixed(0) : v.toFixed(2));
  return el(
    'div',
    { class: 'legend', id: 'legend' },
    el('div', {}, title),
    el('div', { class: 'ramp', style: `background:linear-gradient(to right,${stops})` }),
    el('div', { class: 'ramp-labels' }, el('span', {}, `${fmt(range.min)} ${range.unit}`), el('span', {}, `${fmt(range.max)} ${range.unit}`)),
  );
}

/** A titled section; `body` may be null (then nothing is returned). */
export function section(title, body, id) {
  if (!body) return null;
  return el('section', { id }, el('h2', {}, title), body);
}

/** A list of strings, or null when empty. */
export function list(items, cls) {
  if (!items.length) return null;
  return el('ul', { class: cls }, ...items.map((t) => (t instanceof Node ? el('li', {}, t) : el('li', {}, t))));
}
