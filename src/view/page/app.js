'use strict';
// The viewer's page: controls that edit the view, a frame refined level by level while
// nothing changes (one request in flight: a change aborts it and the server stops its render),
// a click that asks what a pixel shows, and the view saved or rendered to an EXR.

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get('token') || '';
const client = 'c' + Math.random().toString(36).slice(2, 12) + Date.now().toString(36);
const api = (path, query = '') => `${path}?token=${encodeURIComponent(token)}${query}`;

const viewer = { client, info: null, state: null, version: 0, shown: null, lastProbe: null };
window.viewer = viewer;
let inflight = null;
let scheduled = false;
// Every frame request is numbered: the server refuses one older than the newest it has seen.
let seq = 0;

const add = (a, b) => a.map((x, i) => x + b[i]);
const sub = (a, b) => a.map((x, i) => x - b[i]);
const scale = (a, s) => a.map((x) => x * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const unit = (a) => { const n = norm(a); return n > 0 ? scale(a, 1 / n) : a; };
// Rodrigues: a turned by angle about the unit axis k.
const turn = (a, k, angle) => {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(scale(a, c), scale(cross(k, a), s)), scale(k, dot(k, a) * (1 - c)));
};
const fmt = (x, d = 4) => (typeof x === 'number' ? (Math.abs(x) >= 1e4 || (x !== 0 && Math.abs(x) < 1e-3) ? x.toExponential(d) : x.toFixed(d)) : String(x));
const fmt3 = (v) => '(' + v.map((x) => fmt(x, 3)).join(', ') + ')';

function setStatus(text) { $('status').textContent = text; }
function setError(text) {
  const e = $('error');
  e.hidden = !text;
  e.textContent = text || '';
}

/// The view the server renders: the values the controls changed (the rest stay the file's, as
/// it writes them).
function view() {
  const s = viewer.state;
  const t = s.touched;
  const camera = {};
  if (t.has('orbit')) Object.assign(camera, { position: s.camera.position, direction: s.camera.direction });
  if (t.has('time')) camera.time = s.camera.time;
  if (t.has('fov')) camera.fov_y = s.camera.fov_y;
  const groups = {};
  for (const [name, g] of Object.entries(s.groups)) {
    if (t.has('group:' + name)) groups[name] = scale(unit(g.direction), g.beta);
  }
  const v = { groups, camera };
  for (const k of ['doppler', 'searchlight']) if (s[k] !== viewer.info[k]) v[k] = s[k];
  return v;
}

/// A control changed a value of the view.
function touch(what) {
  viewer.state.touched.add(what);
  changed();
}

/// Something changed: one new request per animation frame at most, from the first level.
function changed() {
  viewer.version += 1;
  if (scheduled) return;
  scheduled = true;
  requestAnimationFrame(() => { scheduled = false; request(0); });
}

async function request(level, retries = 3) {
  if (inflight) inflight.abort();
  const ctrl = new AbortController();
  inflight = ctrl;
  const version = viewer.version;
  seq += 1;
  let r, blob;
  try {
    r = await fetch(api('api/frame'), {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ client, seq, level, pass: viewer.state.pass, view: view() }),
      signal: ctrl.signal,
    });
    if (version !== viewer.version || inflight !== ctrl) return;
    if (r.status === 409) {
      // Superseded without a newer request from this page (the server forgot it, say):
      // ask again, a few times.
      if (retries > 0) setTimeout(() => { if (inflight === ctrl) request(level, retries - 1); }, 100);
      return;
    }
    if (!r.ok) {
      setError(await r.text());
      inflight = null;
      return;
    }
    blob = await r.blob();
  } catch (e) {
    if (e.name !== 'AbortError') setError(String(e));
    return;
  }
  if (version !== viewer.version || inflight !== ctrl) return;
  inflight = null;
  setError('');
  const h = (k) => r.headers.get(k);
  const shown = { seq: +h('X-Seq'), level, final: h('X-Final') === 'true', width: +h('X-Width'), height: +h('X-Height'), samples: +h('X-Samples'), ms: +h('X-Render-Ms') };
  const img = $('frame');
  const old = img.src;
  img.src = URL.createObjectURL(blob);
  if (old) URL.revokeObjectURL(old);
  viewer.shown = shown;
  const n = viewer.info.levels.length;
  setStatus(`level ${level + 1} of ${n}: ${shown.width}×${shown.height}, ${shown.samples} sample${shown.samples > 1 ? 's' : ''} a pixel, rendered in ${shown.ms.toFixed(0)} ms${shown.final ? ' (final: as rest-embree render draws it)' : '…'}`);
  document.body.dataset.level = String(level);
  document.body.dataset.final = String(shown.final);
  document.body.dataset.version = String(version);
  if (!shown.final) request(level + 1);
}

function slider(label, min, max, step, value, onInput) {
  const row = document.createElement('label');
  row.textContent = label + ' ';
  const r = Object.assign(document.createElement('input'), { type: 'range', min, max, step, value });
  const n = Object.assign(document.createElement('input'), { type: 'number', min, max, step, value });
  r.addEventListener('input', () => { n.value = r.value; onInput(+r.value); });
  n.addEventListener('change', () => { r.value = n.value; onInput(+n.value); });
  row.append(r, n);
  return { row, range: r, number: n };
}

function groupControls() {
  const box = $('groups');
  for (const g of viewer.info.groups) {
    const div = document.createElement('div');
    div.className = 'group';
    const title = document.createElement('div');
    title.textContent = g.name;
    div.append(title);
    if (!g.editable) {
      const p = document.createElement('p');
      p.className = 'hint';
      p.textContent = 'moves on a worldline: its velocity is the file\'s';
      div.append(p);
      box.append(div);
      continue;
    }
    const beta = norm(g.velocity);
    // A group at rest has no direction of its own: +x until one is typed.
    const st = { beta, direction: beta > 0 ? unit(g.velocity) : [1, 0, 0] };
    viewer.state.groups[g.name] = st;
    const s = slider('β', 0, 0.999, 0.001, beta.toFixed(3), (x) => { st.beta = Math.min(Math.max(x, 0), 0.999999); touch('group:' + g.name); });
    s.range.dataset.group = g.name;
    s.range.classList.add('beta');
    div.append(s.row);
    const dir = document.createElement('label');
    dir.className = 'dir';
    dir.textContent = 'direction ';
    st.direction.forEach((x, i) => {
      const n = Object.assign(document.createElement('input'), { type: 'number', step: 0.1, value: +x.toFixed(4) });
      n.addEventListener('change', () => {
        const d = st.direction.slice();
        d[i] = +n.value;
        if (norm(d) > 0 && d.every(Number.isFinite)) { st.direction = d; touch('group:' + g.name); }
      });
      dir.append(n);
    });
    div.append(dir);
    box.append(div);
  }
}

function cameraControls() {
  const c = viewer.state.camera;
  const t0 = viewer.info.camera.time;
  const [time, timeN] = [$('time'), $('time-n')];
  Object.assign(time, { min: t0 - 20, max: t0 + 20, value: t0 });
  timeN.value = t0;
  time.addEventListener('input', () => { timeN.value = time.value; c.time = +time.value; touch('time'); });
  timeN.addEventListener('change', () => { if (Number.isFinite(+timeN.value)) { time.value = timeN.value; c.time = +timeN.value; touch('time'); } });
  if (viewer.info.camera.fov_y === null) {
    $('fov-row').hidden = true;
  } else {
    $('fov').value = c.fov_y;
    $('fov-n').textContent = c.fov_y.toFixed(1);
    $('fov').addEventListener('input', () => { c.fov_y = +$('fov').value; $('fov-n').textContent = c.fov_y.toFixed(1); touch('fov'); });
  }
  $('reset-camera').addEventListener('click', () => {
    Object.assign(c, structuredClone(viewer.info.camera));
    for (const k of ['orbit', 'time', 'fov']) viewer.state.touched.delete(k);
    c.target = orbitTarget(c);
    time.value = timeN.value = c.time;
    if (c.fov_y !== null) { $('fov').value = c.fov_y; $('fov-n').textContent = c.fov_y.toFixed(1); }
    changed();
  });
  // Orbit about a point ahead: the nearest approach of the view line to the world origin,
  // or 3 ahead.
  c.target = orbitTarget(c);
  const img = $('frame');
  let drag = null;
  img.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, moved: false }; img.setPointerCapture(e.pointerId); });
  img.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) < 2) return;
    drag.moved = true;
    drag.x = e.clientX; drag.y = e.clientY;
    const up = unit(viewer.info.camera.up);
    let off = sub(c.position, c.target);
    off = turn(off, up, -dx * 0.005);
    const right = unit(cross(scale(off, -1), up));
    if (norm(right) > 0) {
      const pitched = turn(off, right, -dy * 0.005);
      if (Math.abs(dot(unit(pitched), up)) < 0.995) off = pitched;
    }
    c.position = add(c.target, off);
    c.direction = unit(scale(off, -1));
    touch('orbit');
  });
  img.addEventListener('pointerup', (e) => {
    const was = drag;
    drag = null;
    if (was && !was.moved) probe(e);
  });
  img.addEventListener('wheel', (e) => {
    e.preventDefault();
    const k = Math.exp(Math.max(-1, Math.min(1, e.deltaY / 500)));
    c.position = add(c.target, scale(sub(c.position, c.target), k));
    touch('orbit');
  }, { passive: false });
}

function orbitTarget(c) {
  const d = unit(c.direction);
  const ahead = -dot(c.position, d);
  return add(c.position, scale(d, ahead > 0.1 ? ahead : 3));
}

/// What the clicked pixel of the frame shown holds.
async function probe(e) {
  const img = $('frame');
  const s = viewer.shown;
  if (!s) return;
  // The picture inside the element's box (object-fit: contain centres it).
  const rect = img.getBoundingClientRect();
  const k = Math.min(rect.width / s.width, rect.height / s.height);
  const left = rect.left + (rect.width - k * s.width) / 2;
  const top = rect.top + (rect.height - k * s.height) / 2;
  const x = Math.floor((e.clientX - left) / k);
  const y = Math.floor((e.clientY - top) / k);
  if (x < 0 || y < 0 || x >= s.width || y >= s.height) return;
  const m = $('marker');
  m.hidden = false;
  m.style.left = `${e.clientX - rect.left}px`;
  m.style.top = `${e.clientY - rect.top}px`;
  const r = await fetch(api('api/probe', `&client=${client}&seq=${s.seq}&x=${x}&y=${y}`));
  if (!r.ok) { setError(await r.text()); return; }
  const p = await r.json();
  viewer.lastProbe = p;
  const box = $('info');
  box.replaceChildren(Object.assign(document.createElement('legend'), { textContent: 'At the clicked pixel' }));
  const rows = p.hit ? [
    ['pixel', `${x}, ${y} of ${s.width}×${s.height}`],
    ['object', `${p.object ?? '(unnamed)'} (${p.kind}, #${p.object_id})`],
    ['group', p.group],
    ['emitted at t', fmt(p.emission.t)],
    ['from x', fmt3(p.emission.x)],
    ['lookback', fmt(p.lookback)],
    ['Doppler factor', fmt(p.doppler)],
    ['depth', fmt(p.depth)],
    ['on the object (rest frame)', fmt3(p.rest_position)],
  ] : [['pixel', `${x}, ${y}`], ['object', 'nothing: the background']];
  const table = document.createElement('table');
  table.id = 'probe';
  for (const [k, v] of rows) {
    const tr = table.insertRow();
    tr.insertCell().textContent = k;
    tr.insertCell().textContent = v;
  }
  box.append(table);
  document.body.dataset.probe = JSON.stringify(p);
}

async function save() {
  const r = await fetch(api('api/save'), { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ view: view() }) });
  if (!r.ok) { setError(await r.text()); return; }
  const blob = await r.blob();
  const name = (r.headers.get('Content-Disposition') || '').match(/filename="([^"]+)"/)?.[1] || 'view.toml';
  const a = Object.assign(document.createElement('a'), { href: URL.createObjectURL(blob), download: name });
  document.body.append(a);
  a.click();
  a.remove();
}

async function renderExr() {
  const r = await fetch(api('api/render'), { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ view: view() }) });
  if (!r.ok) { setError(await r.text()); return; }
  let job = await r.json();
  const bar = $('progress');
  bar.hidden = false;
  const link = (name) => `<a href="${api('files/' + name)}" download="${name}">${name}</a>`;
  while (job.state === 'running') {
    bar.value = job.progress;
    $('job').textContent = `rendering ${job.exr}: ${(100 * job.progress).toFixed(0)}%`;
    await new Promise((ok) => setTimeout(ok, 400));
    const q = await fetch(api('api/job', `&id=${job.id}`));
    if (!q.ok) { setError(await q.text()); return; }
    job = await q.json();
  }
  bar.value = 1;
  $('job').innerHTML = job.state === 'done' ? `${link(job.exr)} and its scene ${link(job.toml)}` : '';
  if (job.state !== 'done') setError(job.error);
}

async function init() {
  const r = await fetch(api('api/scene'));
  if (!r.ok) { setError(await r.text()); return; }
  viewer.info = await r.json();
  const c = structuredClone(viewer.info.camera);
  viewer.state = { groups: {}, camera: c, doppler: viewer.info.doppler, searchlight: viewer.info.searchlight, pass: 'colour', touched: new Set() };
  $('file').textContent = viewer.info.file;
  groupControls();
  cameraControls();
  for (const k of ['doppler', 'searchlight']) {
    $(k).checked = viewer.state[k];
    $(k).addEventListener('change', () => { viewer.state[k] = $(k).checked; changed(); });
  }
  for (const p of viewer.info.passes) $('pass').append(new Option(p.replace('_', ' '), p));
  $('pass').addEventListener('change', () => { viewer.state.pass = $('pass').value; changed(); });
  $('save').addEventListener('click', save);
  $('render').addEventListener('click', renderExr);
  changed();
}

init();
