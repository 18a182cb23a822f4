// explore.js — the page of edgespace explore (python/edgespace/explore/
// server.py serves it). Sliders send their position over a WebSocket; the
// server embeds it and sends the mesh back as one binary message (a JSON
// header, then float64 positions and heat maps). The server keeps only the
// newest position pending, so a drag never queues up old ones.
//
// window.esExplorer exposes the page's state to tests and benchmarks: the
// last shape received (its float64 positions as they arrived), the timings
// of every request (input, sent, received, drawn: performance.now() ms),
// the errors shown, and send() for a raw request.
import { Scatter } from './scatter.js';
import { fmt } from './util.js';

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get('token') || '';
const state = {
  info: null, coords: {}, seq: 0, timings: {}, last: null, errors: [], saved: [],
  ready: false, view: null, socket: null, heat: '', closed: false,
};
window.esExplorer = {
  state,
  get last() { return state.last; },
  get errors() { return state.errors; },
  get timings() { return Object.values(state.timings); },
  send: (req) => send(req),
  png: () => png(),
  setSlider: (key, value) => setSlider(key, value, true),
};

function showError(message) {
  state.errors.push(message);
  const e = $('error');
  e.textContent = message;
  e.hidden = false;
}
function clearError() { $('error').hidden = true; }

async function get(path, kind) {
  const r = await fetch(path, { headers: { 'X-Edgespace-Token': token } });
  if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
  return kind === 'json' ? r.json() : r.arrayBuffer();
}

function send(req) {
  if (!state.socket || state.socket.readyState !== WebSocket.OPEN) {
    showError('not connected to the explorer: reload the page, or start `edgespace explore` again');
    return null;
  }
  req.seq = ++state.seq;
  state.socket.send(JSON.stringify(req));
  return req.seq;
}

// -- sliders ----------------------------------------------------------------
function buildSliders(directions) {
  const box = $('sliders');
  for (const d of directions) {
    const row = document.createElement('div');
    row.className = 'slider';
    const label = document.createElement('label');
    label.textContent = d.label;
    label.title = `${d.term}: ${d.lo} to ${d.hi} ${d.unit}`;
    const range = document.createElement('input');
    Object.assign(range, { type: 'range', min: d.lo, max: d.hi, step: d.step, value: 0 });
    range.id = `s-${d.key}`;
    range.setAttribute('aria-label', d.label);
    const text = document.createElement('input');
    Object.assign(text, { type: 'text', value: '0', inputMode: 'decimal' });
    text.id = `t-${d.key}`;
    text.title = `${d.unit}; type a value and press Enter`;
    range.addEventListener('input', () => {
      text.value = range.value;
      text.classList.remove('bad');
      moved(d.key, Number(range.value));
    });
    text.addEventListener('change', () => {
      // sent as typed when it is not a plain number: the server says what is wrong
      const v = text.value.trim();
      const n = /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(v) ? Number(v) : v;
      if (typeof n === 'number') range.value = n;
      text.classList.toggle('bad', typeof n !== 'number');
      moved(d.key, n);
    });
    row.append(label, range, text);
    box.append(row);
  }
}

function setSlider(key, value, fire) {
  const range = $(`s-${key}`), text = $(`t-${key}`);
  if (!range) return;
  range.value = value;
  text.value = typeof value === 'number' ? +value.toFixed(4) : value;
  text.classList.remove('bad');
  if (fire) range.dispatchEvent(new Event('input'));
}

// Sliders and coordinates set to a position t ({key: value}), nothing sent.
function showPosition(t) {
  state.coords = { ...t };
  for (const d of state.info.directions) setSlider(d.key, t[d.key] || 0, false);
  state.scatter.mark(state.coords);
}

function moved(key, value) {
  const tInput = performance.now();
  if (value === 0) delete state.coords[key]; else state.coords[key] = value;
  const seq = send({ op: 'embed', coords: { ...state.coords } });
  if (seq !== null) state.timings[seq] = { seq, key, value, tInput, tSent: performance.now() };
  state.scatter.mark(state.coords);
}

// -- shapes -----------------------------------------------------------------
function onShape(buf) {
  const tRecv = performance.now();
  const n = new DataView(buf).getUint32(0, true);
  const hdr = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, n)));
  const V = hdr.nverts, off = 4 + n;
  const positions = new Float64Array(buf, off, 3 * V);
  const heat = {};
  hdr.heat.forEach((h, i) => { heat[h.name] = { data: new Float64Array(buf, off + 8 * V * (3 + i), V), ...h }; });
  state.last = { ...hdr, positions, heat };
  clearError();
  if (hdr.row !== null) showPosition(hdr.t);   // a row: the sliders show its scores
  $('expr').value = hdr.expr;
  $('cmd').textContent = hdr.command;
  const w = $('warning');
  w.hidden = !hdr.warning;
  w.textContent = hdr.warning ? `⚠ ${hdr.warning}` : '';
  const r = hdr.report;
  $('status').textContent = r
    ? `edge lengths: RMS ${fmt(100 * r.rms_ratio)} %, max ${fmt(100 * r.max_rel)} % · ` +
      `${r.lg_iters} iterations · bending ${fmt(r.bend_ratio)} × the prior's · ` +
      `server ${(1000 * hdr.seconds).toFixed(0)} ms`
    : `row ${hdr.row} as ingested, aligned into the store's frame`;
  drawShape();
  const t = state.timings[hdr.seq];
  if (t) {
    Object.assign(t, { tRecv, server: hdr.seconds, serverCpu: hdr.cpu_seconds });
    requestAnimationFrame(() => { t.tDrawn = performance.now(); });
  }
}

function drawShape() {
  const s = state.last;
  if (!s || !state.view) return;
  const h = state.heat && s.heat[state.heat];
  state.view.update(s.positions, h ? h.data : null, h || null);
}

function onText(msg) {
  if (msg.op === 'error') {
    showError(msg.message);
    const t = state.timings[msg.seq];
    if (t) {
      t.error = msg.message;
      // the newest position was refused: the sliders go back to the shape on screen
      if (msg.seq === state.seq && state.last) showPosition(state.last.t);
    }
  } else if (msg.op === 'superseded') {
    if (state.timings[msg.seq]) state.timings[msg.seq].superseded = true;
  } else if (msg.op === 'saved') {
    state.saved.push(msg);
    const a = document.createElement('a');
    a.href = `${msg.url}?token=${encodeURIComponent(token)}`;
    a.textContent = msg.file;
    a.download = msg.file;
    $('saved').replaceChildren('saved ', a, ` in the store's folder and the point as /analysis/${msg.point}`);
  }
}

// -- the page -----------------------------------------------------------------
function png() {
  const s = state.last;
  return state.view ? state.view.png(s ? s.expr : '') : null;
}

function connect() {
  const ws = new WebSocket(`ws://${location.host}/ws?token=${encodeURIComponent(token)}`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { state.socket = ws; moved('', 0); };
  ws.onmessage = (e) => (typeof e.data === 'string' ? onText(JSON.parse(e.data)) : onShape(e.data));
  ws.onclose = () => {
    state.closed = true;
    showError('the connection to the explorer closed (the server stopped, or a request was too large): reload the page');
  };
}

function copy(text) {
  navigator.clipboard.writeText(text).catch(() => {
    const t = document.createElement('textarea');
    t.value = text;
    document.body.append(t);
    t.select();
    document.execCommand('copy');
    t.remove();
  });
}

async function main() {
  const info = await get(`/api/info?token=${encodeURIComponent(token)}`, 'json');
  state.info = info;
  $('title').textContent = `${info.store}: ${info.nrows} rows, ${info.nverts} vertices · PCA ${info.pca}` +
    ` · ${info.warm ? 'warm' : 'cold'} starts, ${info.fast ? 'slider' : 'full'} accuracy`;
  document.title = `edgespace explore: ${info.store}`;
  buildSliders(info.directions);
  for (const [name, label] of Object.entries(info.heat_maps)) $('heat').append(new Option(label, name));
  for (const f of info.formats) $('save-format').append(new Option(f, f));
  state.scatter = new Scatter($('scatter'), $('legend'), $('hover'), info,
    (id) => send({ op: 'row', id }), $('sx'), $('sy'), $('color'));
  const faces = new Int32Array(await get(`/api/faces?token=${encodeURIComponent(token)}`));
  try {
    if (!info.three) throw new Error('three.js is not installed on the server (tools/setup.sh installs it)');
    const { MeshView } = await import('./view3d.js');   // three.js: only where it is there
    state.view = new MeshView($('canvas-box'), {
      box: $('colorbar'), canvas: $('cb-canvas'), min: $('cb-min'), max: $('cb-max'), label: $('cb-label'),
    }, faces, info.nverts, info.view);
  } catch (e) {
    showError(`the mesh cannot be drawn here (${e.message}); the shapes still arrive`);
  }
  $('heat').addEventListener('change', () => { state.heat = $('heat').value; drawShape(); });
  $('reset').addEventListener('click', () => {
    state.coords = {};
    for (const d of info.directions) setSlider(d.key, 0, false);
    moved('', 0);
  });
  $('copy-expr').addEventListener('click', () => copy($('expr').value));
  $('copy-cmd').addEventListener('click', () => copy($('cmd').textContent));
  $('png').addEventListener('click', () => {
    const a = document.createElement('a');
    a.href = png();
    a.download = `${$('save-name').value || 'edgespace-explore'}.png`;
    a.click();
  });
  $('save').addEventListener('click', () => {
    if (!state.last) return;
    send({ op: 'save', shape: state.last.seq, name: $('save-name').value, format: $('save-format').value });
  });
  connect();
  state.ready = true;
}

main().catch((e) => showError(`the explorer could not start: ${e.message}`));
