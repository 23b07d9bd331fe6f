// Decoding of the number streams the page carries (see src/view/encode.rs): base64,
// LEB128 varints, zigzag deltas in micrometres, run-length pairs.

/** Bytes of a base64 string. */
export function bytes(b64) {
  const text = atob(b64 || '');
  const out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
  return out;
}

/** Every unsigned varint of a base64 string, as numbers (exact up to 2^53). */
export function varints(b64) {
  const b = bytes(b64);
  const out = [];
  let v = 0;
  let scale = 1;
  for (let i = 0; i < b.length; i++) {
    const byte = b[i];
    v += (byte & 0x7f) * scale;
    if (byte & 0x80) {
      scale *= 128;
    } else {
      out.push(v);
      v = 0;
      scale = 1;
    }
  }
  return out;
}

/** Zigzag back to signed. */
export function unzigzag(v) {
  return v % 2 === 0 ? v / 2 : -(v + 1) / 2;
}

/** Delta-encoded µm positions as a Float32Array of mm [x, y, z, ...]. */
export function positions(b64, count) {
  const v = varints(b64);
  const out = new Float32Array(count * 3);
  const last = [0, 0, 0];
  for (let i = 0; i < count * 3 && i < v.length; i++) {
    const axis = i % 3;
    last[axis] += unzigzag(v[i]);
    out[i] = last[axis] / 1000;
  }
  return out;
}

/** A run-length stream expanded to `count` values. */
export function runLengths(b64, count) {
  const v = varints(b64);
  const out = new Float64Array(count);
  let k = 0;
  for (let i = 0; i + 1 < v.length && k < count; i += 2) {
    for (let r = 0; r < v[i + 1] && k < count; r++) out[k++] = v[i];
  }
  return out;
}

/** Zigzag-delta indices as a Uint32Array. */
export function deltaIndices(b64, count) {
  const v = varints(b64);
  const out = new Uint32Array(count);
  let last = 0;
  for (let i = 0; i < count && i < v.length; i++) {
    last += unzigzag(v[i]);
    out[i] = last;
  }
  return out;
}
