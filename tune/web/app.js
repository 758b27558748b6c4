// skinlab tune: the page. Every control is built from /api/schema (the declarations the scene reader uses), every
// change becomes a `--set` override, and at most one render request of this tab is in flight: while it runs, later
// changes only mark the state dirty, and the newest state is sent when the answer arrives (latest wins).
'use strict';

const token = new URLSearchParams(location.hash.slice(1)).get('token') || '';
// This start's token (the server writes it into the page): sent with every request, as the server requires for
// POSTs; another site's page cannot read it.
const pageToken = document.querySelector('meta[name="skinlab-token"]').content;
const client = 'tab-' + Math.random().toString(36).slice(2, 10);
const $ = (id) => document.getElementById(id);

let schema = null;
let scene = '';
const overrides = new Map(); // key → TOML value text, in the order first set
let resolved = null;
let inFlight = false;
let dirty = false;
let sequence = 0;
let referenceJob = null; // id of the reference job of the current scene/view/lights
let referenceFor = '';    // the configuration (without [sss] keys) it was computed for
let slowJob = null;      // id of a running background render of a slow method
let pinned = null;       // {src, caption}
let flickerTimer = null;
let lastImage = '';
let refreshers = []; // {key, element, apply(value)}: controls shown with the last resolved values

function headers(extra) {
  const h = Object.assign({ 'X-Skinlab-Token': pageToken }, extra || {});
  if (token) h['Authorization'] = 'Bearer ' + token;
  return h;
}

// A JSON request; a refusal throws an Error with the server's line, its status and its answer.
async function api(path, body) {
  const options = body === undefined ? { headers: headers() }
    : { method: 'POST', headers: headers({ 'Content-Type': 'application/json' }), body: JSON.stringify(body) };
  const response = await fetch(path, options);
  let data = null;
  try { data = await response.json(); } catch (e) { data = { error: 'answer is not JSON (' + response.status + ')' }; }
  if (!response.ok) {
    const error = new Error(data && data.error ? data.error : 'HTTP ' + response.status);
    error.status = response.status;
    error.data = data;
    throw error;
  }
  return data;
}

function showError(message) {
  const line = $('error');
  if (message) { line.textContent = 'skinlab: error: ' + message; line.hidden = false; }
  else { line.textContent = ''; line.hidden = true; }
}

// A value as TOML text (what `--set key=value` takes).
function tomlValue(value) {
  if (Array.isArray(value)) return '[' + value.map(tomlValue).join(', ') + ']';
  if (typeof value === 'string') return JSON.stringify(value);
  return String(value);
}

function setOverride(key, text) {
  overrides.set(key, text);
  schedule();
}

function overrideList() {
  return Array.from(overrides, ([k, v]) => k + '=' + v);
}

function config() { return { scene, overrides: overrideList() }; }

function valueAt(path) {
  if (!resolved) return undefined;
  let node = resolved;
  for (const part of path.split('.')) {
    const m = /^(\w+)\[(\d+)\]$/.exec(part);
    if (m) node = node && node[m[1]] ? node[m[1]][Number(m[2])] : undefined;
    else node = node ? node[part] : undefined;
    if (node === undefined) return undefined;
  }
  return node;
}

// --- controls -----------------------------------------------------------------------------------------------

function logScale(declaration) { return declaration.min > 0 && declaration.max / declaration.min >= 100; }
function toSlider(declaration, value) {
  if (logScale(declaration)) return 1000 * Math.log(value / declaration.min) / Math.log(declaration.max / declaration.min);
  return value;
}
function fromSlider(declaration, position) {
  if (logScale(declaration)) return declaration.min * Math.pow(declaration.max / declaration.min, position / 1000);
  return position;
}
function rounded(value) { return Number(Number(value).toPrecision(4)); }

// One control for a declared key: {name, type, min, max, choices, unit, doc, default}; `key` is the dotted path.
function keyControl(key, declaration) {
  const row = document.createElement('div');
  row.className = 'key';
  row.title = declaration.doc || '';
  const name = document.createElement('span');
  name.className = 'name';
  name.textContent = key.replace(/^(sss|transmittance)\./, '') + ' ';
  row.append(name);
  const current = valueAt(key) !== undefined ? valueAt(key) : declaration.default;
  const type = declaration.type;
  if (type === 'boolean') {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.dataset.key = key;
    box.checked = !!current;
    box.addEventListener('change', () => setOverride(key, String(box.checked)));
    refreshers.push({ key, elements: [box], apply: (v) => { box.checked = !!v; } });
    row.append(box);
  } else if (type === 'choice') {
    const select = document.createElement('select');
    select.dataset.key = key;
    for (const c of declaration.choices) select.append(new Option(c, c));
    select.value = current;
    select.addEventListener('change', () => setOverride(key, tomlValue(select.value)));
    refreshers.push({ key, elements: [select], apply: (v) => { select.value = v; } });
    row.append(select);
  } else if (type === 'string') {
    const input = document.createElement('input');
    input.dataset.key = key;
    input.value = current === undefined ? '' : current;
    input.setAttribute('list', 'profiles');
    input.addEventListener('change', () => setOverride(key, tomlValue(input.value)));
    refreshers.push({ key, elements: [input], apply: (v) => { input.value = v; } });
    row.append(input);
  } else if (type === 'vec3') {
    const values = Array.isArray(current) ? current.slice() : [0, 0, 0];
    const parts = [];
    ['R', 'G', 'B'].forEach((channel, i) => {
      const line = document.createElement('div');
      const slider = document.createElement('input');
      slider.type = 'range';
      slider.min = declaration.min; slider.max = declaration.max; slider.step = (declaration.max - declaration.min) / 200;
      slider.value = values[i];
      slider.dataset.key = key + '[' + i + ']';
      const number = document.createElement('input');
      number.type = 'number'; number.step = 'any'; number.value = values[i];
      const update = (v) => { values[i] = rounded(v); setOverride(key, tomlValue(values)); };
      slider.addEventListener('input', () => { number.value = rounded(slider.value); update(slider.value); });
      number.addEventListener('change', () => { slider.value = number.value; update(number.value); });
      line.append(channel + ' ', slider, ' ', number);
      parts.push([slider, number]);
      row.append(line);
    });
    refreshers.push({ key, elements: parts.flat(), apply: (v) => {
      if (!Array.isArray(v)) return;
      v.forEach((x, i) => { values[i] = x; parts[i][0].value = x; parts[i][1].value = x; });
    } });
  } else { // number, integer
    const slider = document.createElement('input');
    slider.type = 'range';
    slider.dataset.key = key;
    const number = document.createElement('input');
    number.type = 'number';
    number.step = 'any';
    number.dataset.keyNumber = key;
    if (type === 'integer') {
      slider.min = declaration.min; slider.max = declaration.max;
      slider.step = key === 'sss.samples' ? 2 : 1; // odd taps: 3, 5, ... 101
    } else if (logScale(declaration)) {
      slider.min = 0; slider.max = 1000; slider.step = 1;
    } else {
      slider.min = declaration.min; slider.max = declaration.max; slider.step = (declaration.max - declaration.min) / 500;
    }
    slider.value = toSlider(declaration, current);
    number.value = current;
    slider.addEventListener('input', () => {
      const v = type === 'integer' ? Number(slider.value) : rounded(fromSlider(declaration, Number(slider.value)));
      number.value = v;
      setOverride(key, String(v));
    });
    // Typed values go to the server as typed: a bad one is answered with the reader's one-line error.
    number.addEventListener('change', () => {
      if (number.value.trim() === '') return;
      slider.value = toSlider(declaration, Number(number.value));
      setOverride(key, number.value.trim());
    });
    refreshers.push({ key, elements: [slider, number], apply: (v) => {
      slider.value = toSlider(declaration, v);
      number.value = v;
    } });
    row.append(slider, ' ', number);
  }
  if (declaration.unit) {
    const unit = document.createElement('span');
    unit.className = 'unit';
    unit.textContent = ' ' + declaration.unit;
    row.append(unit);
  }
  return row;
}

function methodInfo(name) { return schema.methods.find((m) => m.name === name); }

function buildMethodControls() {
  const method = valueAt('sss.method') || 'none';
  $('method').value = method;
  const info = methodInfo(method);
  $('method-summary').textContent = info ? info.summary : '';
  const box = $('method-keys');
  box.replaceChildren();
  for (const p of info ? info.parameters : []) box.append(keyControl('sss.' + p.name, p));
  const t = $('transmittance-keys');
  t.replaceChildren();
  for (const p of schema.transmittance) t.append(keyControl('transmittance.' + p.name, p));
}

function buildViewControls() {
  const box = $('view-keys');
  box.replaceChildren();
  box.append(keyControl('camera.view', { type: 'choice', choices: schema.views, doc: 'named view' }));
  box.append(keyControl('camera.yaw_deg', { type: 'number', min: -180, max: 180, unit: '°', doc: 'orbit about +Y (drag the image)' }));
  box.append(keyControl('camera.pitch_deg', { type: 'number', min: -89, max: 89, unit: '°', doc: 'orbit upwards (drag the image)' }));
  box.append(keyControl('render.exposure_ev', { type: 'number', min: -6, max: 6, unit: 'EV', doc: 'exposure' }));
  box.append(keyControl('tone_map.operator', { type: 'choice', choices: schema.tone_maps, doc: 'tone mapper' }));
  const lights = $('light-keys');
  lights.replaceChildren();
  (valueAt('lights') || []).forEach((light, i) => {
    const row = keyControl('lights[' + i + '].intensity',
      { type: 'number', min: 0, max: Math.max(4, 4 * light.intensity), doc: light.type + ' light' });
    row.querySelector('.name').textContent = 'light ' + i + ' (' + light.type + ') intensity ';
    lights.append(row);
  });
}

// Controls show the resolved values of the last render (the one being dragged keeps its position).
function refreshControls(rebuild) {
  if (rebuild) {
    refreshers = [];
    buildMethodControls();
    buildViewControls();
    return;
  }
  for (const r of refreshers) {
    if (r.elements.includes(document.activeElement)) continue;
    const v = valueAt(r.key);
    if (v !== undefined) r.apply(v);
  }
}

// --- rendering ----------------------------------------------------------------------------------------------

function schedule() {
  dirty = true;
  if (!inFlight) send();
}

async function send() {
  dirty = false;
  inFlight = true;
  const mine = ++sequence;
  const body = Object.assign({ client, seq: mine }, config());
  const lightingNow = scene + '|' + overrideList().filter((o) => !o.startsWith('sss.') && !o.startsWith('tone_map.')).join('|');
  const compareOn = $('mode').value === 'difference' && referenceJob && referenceFor === lightingNow;
  if ($('mode').value === 'difference' && referenceJob && !compareOn)
    $('job-status').textContent = 'the reference is for another view, size or lighting: compute it again';
  if (compareOn) body.compare = { reference: referenceJob, metric: $('metric').value };
  const started = performance.now();
  try {
    const answer = await api('/api/render', body);
    if (answer.superseded) return;
    showError('');
    const previousMethod = valueAt('sss.method');
    const previousLights = JSON.stringify(valueAt('lights'));
    resolved = answer.resolved;
    refreshControls(previousMethod !== valueAt('sss.method') || previousLights !== JSON.stringify(valueAt('lights')));
    $('params').textContent = JSON.stringify({ scene, overrides: overrideList(), resolved: answer.resolved }, null, 1);
    if (answer.job) { followJob(answer.job.id, true); return; }
    slowJob = null;
    showImage(answer.image, answer);
    const roundTrip = performance.now() - started;
    $('status').textContent = `#${mine} ${answer.width}×${answer.height}: ${roundTrip.toFixed(0)} ms from input to image ` +
      `(render ${answer.render_ms.toFixed(0)} ms, re-ran ${answer.reran.join(' + ')})`;
    fillTimings(answer, roundTrip);
    if (answer.compare) showComparison(answer.compare);
    updateKernel();
  } catch (e) {
    showError(e.message);
    $('status').textContent = 'error';
  } finally {
    inFlight = false;
    if (dirty) send();
  }
}

function showImage(src, answer) {
  lastImage = src;
  $('image').src = src;
  $('caption').textContent = 'current: ' + (valueAt('sss.method') || '') + (answer ? ' (' + answer.width + '×' + answer.height + ')' : '');
  applyMode();
}

function fillTimings(answer, roundTrip) {
  const rows = [['input → image', roundTrip], ['server', answer.server_ms], ['render', answer.render_ms], ['queued', answer.queued_ms]];
  const passes = (answer.timings && answer.timings.passes) || {};
  for (const [name, ms] of Object.entries(passes)) rows.push(['  ' + name, ms]);
  if (answer.compare && answer.compare.ms !== undefined) rows.push(['metrics', answer.compare.ms]);
  const body = $('timings').querySelector('tbody');
  body.replaceChildren(...rows.map(([name, ms]) => {
    const tr = document.createElement('tr');
    tr.innerHTML = '<td></td><td></td>';
    tr.children[0].textContent = name;
    tr.children[1].textContent = Number(ms).toFixed(1);
    return tr;
  }));
}

function showComparison(c) {
  if (c.pending) { $('job-status').textContent = 'reference ' + c.state; return; }
  $('image-diff').src = c.image;
  const jod = c.jod === null ? '–' : c.jod.toFixed(2);
  $('caption-diff').textContent = `${c.metric} against the reference · JOD ${jod} · ΔE00 mean ${fmt(c.delta_e00_mean)}`;
  const body = $('bands').querySelector('tbody');
  body.replaceChildren(...Object.entries(c.bands).map(([band, s]) => {
    const tr = document.createElement('tr');
    for (const v of [band, s.pixels, fmt(s.delta_e00_mean), fmt(s.delta_e00_p95), fmt(s.flip_mean, 3), fmt(s.excess)]) {
      const td = document.createElement('td');
      td.textContent = v;
      tr.append(td);
    }
    return tr;
  }));
  $('bands').hidden = false;
}

function fmt(v, digits) { return v === null || v === undefined ? '–' : Number(v).toFixed(digits || 2); }

// --- view modes: A/B side by side, flicker, difference -------------------------------------------------------

function applyMode() {
  const mode = $('mode').value;
  clearInterval(flickerTimer);
  flickerTimer = null;
  $('figure-a').hidden = !(mode === 'side' && pinned);
  $('figure-diff').hidden = mode !== 'difference';
  $('rate-label').hidden = mode !== 'flicker';
  $('image').src = lastImage;
  if (mode === 'side' && pinned) { $('image-a').src = pinned.src; $('caption-a').textContent = pinned.caption; }
  if (mode === 'flicker' && pinned) {
    let showA = false;
    const rate = Number($('rate').value);
    flickerTimer = setInterval(() => {
      showA = !showA;
      $('image').src = showA ? pinned.src : lastImage;
      $('caption').textContent = showA ? pinned.caption : 'current';
    }, 500 / rate);
  }
}

// --- background jobs (reference, slow methods) ---------------------------------------------------------------

async function followJob(id, isRender) {
  if (isRender) slowJob = id;
  $('cancel').hidden = false;
  $('cancel').dataset.job = id;
  const progress = $('progress');
  progress.hidden = false;
  for (;;) {
    let status;
    try { status = await api('/api/job?id=' + encodeURIComponent(id)); } catch (e) { showError(e.message); break; }
    if (status.expected_s) { progress.max = 1; progress.value = Math.min(0.99, status.elapsed_s / status.expected_s); }
    else progress.removeAttribute('value');
    $('job-status').textContent = `${status.method} ${status.state}: ${status.elapsed_s.toFixed(1)} s` +
      (status.expected_s ? ` of about ${status.expected_s.toFixed(0)} s` : '');
    if (status.state === 'done') {
      if (isRender && slowJob === id) {
        const response = await fetch('/api/job/image?id=' + encodeURIComponent(id), { headers: headers() });
        showImage(URL.createObjectURL(await response.blob()), null);
      }
      if (!isRender && $('mode').value === 'difference') schedule();
      break;
    }
    if (status.state !== 'running') {
      if (status.state === 'failed') showError(status.error);
      break;
    }
    if (isRender && slowJob !== id) break;
    await new Promise((r) => setTimeout(r, 500));
  }
  progress.hidden = true;
  $('cancel').hidden = true;
}

// --- kernel curves ---------------------------------------------------------------------------------------------

let kernelKey = '';
async function updateKernel() {
  const sssOverrides = overrideList().filter((o) => o.startsWith('sss.'));
  const key = scene + '|' + sssOverrides.join('|');
  if (key === kernelKey) return;
  kernelKey = key;
  try { drawKernel(await api('/api/kernel', { scene, overrides: sssOverrides })); } catch (e) { /* shown by the render */ }
}

function drawKernel(k) {
  const svg = $('kernel');
  const W = 640, H = 260, left = 48, right = 150, top = 10, bottom = 30;
  const xs = k.radius_mm;
  const xMax = xs[xs.length - 1];
  const all = [];
  for (const set of [k.deon, k.burley, k.method_curve || []]) for (const ch of set) for (const v of ch) if (v > 0) all.push(v);
  for (const stage of k.stages) for (const t of stage.taps) for (const v of t.density) if (v > 0) all.push(v);
  const yMax = Math.log10(Math.max(...all, 1e-6));
  const yMin = yMax - 4;
  const X = (x) => left + (W - left - right) * x / xMax;
  const Y = (v) => top + (H - top - bottom) * (1 - (Math.log10(Math.max(v, Math.pow(10, yMin))) - yMin) / (yMax - yMin));
  const colours = ['#c62828', '#2e7d32', '#1565c0'];
  let out = '';
  for (let d = Math.ceil(yMin); d <= Math.floor(yMax); d++)
    out += `<line class="grid" x1="${left}" x2="${W - right}" y1="${Y(Math.pow(10, d))}" y2="${Y(Math.pow(10, d))}"/>` +
      `<text x="${left - 4}" y="${Y(Math.pow(10, d)) + 4}" text-anchor="end">1e${d}</text>`;
  for (let i = 0; i <= 5; i++) {
    const x = xMax * i / 5;
    out += `<text x="${X(x)}" y="${H - 12}" text-anchor="middle">${x.toFixed(1)}</text>`;
  }
  out += `<text x="${(left + W - right) / 2}" y="${H - 1}" text-anchor="middle">radius on the surface (mm)</text>`;
  out += `<line class="axis" x1="${left}" x2="${left}" y1="${top}" y2="${H - bottom}"/><line class="axis" x1="${left}" x2="${W - right}" y1="${H - bottom}" y2="${H - bottom}"/>`;
  const path = (values, c, dash) => `<polyline fill="none" stroke="${colours[c]}" stroke-width="1.4" ${dash ? `stroke-dasharray="${dash}"` : ''} points="` +
    values.map((v, i) => `${X(xs[i]).toFixed(1)},${Y(v).toFixed(1)}`).join(' ') + '"/>';
  for (let c = 0; c < 3; c++) {
    out += path(k.deon[c], c, '5 3') + path(k.burley[c], c, '1 3');
    if (k.method_curve) out += path(k.method_curve[c], c, '');
    for (const stage of k.stages)
      for (const t of stage.taps)
        if (t.offset_mm <= xMax && t.density[c] > 0)
          out += `<circle cx="${X(t.offset_mm).toFixed(1)}" cy="${Y(t.density[c]).toFixed(1)}" r="2.2" fill="${colours[c]}"/>`;
  }
  const legend = [['method' + (k.method_curve ? '' : ' (taps only)'), ''], ["d'Eon", '5 3'], ['Burley', '1 3']];
  legend.forEach(([label, dash], i) => {
    const y = top + 14 + i * 16;
    out += `<line x1="${W - right + 10}" x2="${W - right + 34}" y1="${y}" y2="${y}" stroke="#333" ${dash ? `stroke-dasharray="${dash}"` : ''}/>` +
      `<text x="${W - right + 38}" y="${y + 4}">${label}</text>`;
  });
  out += `<text x="${W - right + 10}" y="${top + 72}">${k.stages.reduce((n, s) => n + s.taps.length, 0)} taps ≥ 0 shown</text>`;
  out += `<text x="${W - right + 10}" y="${top + 88}">support ${k.support_mm.toFixed(2)} mm</text>`;
  svg.innerHTML = out;
}

// --- start ---------------------------------------------------------------------------------------------------

function resetForScene() {
  overrides.clear();
  overrides.set('render.width', String(schema.width));
  overrides.set('render.height', String(schema.height));
  if (schema.method) overrides.set('sss.method', tomlValue(schema.method));
  referenceJob = null;
  $('bands').hidden = true;
}

async function start() {
  try { schema = await api('/api/schema'); } catch (e) { showError(e.message); return; }
  for (const s of schema.scenes) $('scene').append(new Option(s, s));
  scene = schema.scenes[0];
  for (const m of schema.methods) $('method').append(new Option(m.name + (m.slow ? ' (slow)' : ''), m.name));
  const sizes = [[schema.width, schema.height], [320, 180], [640, 360], [1280, 720]];
  const seen = new Set();
  for (const [w, h] of sizes) {
    if (seen.has(w + 'x' + h)) continue;
    seen.add(w + 'x' + h);
    $('size').append(new Option(w + '×' + h, w + 'x' + h));
  }
  const profiles = document.createElement('datalist');
  profiles.id = 'profiles';
  for (const p of ['deon', 'burley']) profiles.append(new Option(p, p));
  document.body.append(profiles);
  schema.stimuli.forEach((s, i) => $('stimulus').append(new Option(s.set + ': ' + s.id, s.set_index + '|' + s.id)));
  $('open').disabled = schema.stimuli.length === 0;
  resetForScene();

  $('scene').addEventListener('change', () => { scene = $('scene').value; resetForScene(); resolved = null; schedule(); });
  $('size').addEventListener('change', () => {
    const [w, h] = $('size').value.split('x');
    overrides.set('render.width', w);
    setOverride('render.height', h);
  });
  $('method').addEventListener('change', () => {
    // The keys of the previous method would be refused by the reader ("not a parameter of method ..."): drop them.
    const info = methodInfo($('method').value);
    const keep = new Set(info.parameters.map((p) => 'sss.' + p.name));
    for (const key of Array.from(overrides.keys())) if (key.startsWith('sss.') && !keep.has(key)) overrides.delete(key);
    setOverride('sss.method', tomlValue($('method').value));
  });
  $('mode').addEventListener('change', () => { applyMode(); if ($('mode').value === 'difference') schedule(); });
  $('metric').addEventListener('change', () => { if ($('mode').value === 'difference') schedule(); });
  $('rate').addEventListener('input', () => { $('rate-value').textContent = $('rate').value + ' Hz'; applyMode(); });
  $('pin').addEventListener('click', () => {
    pinned = { src: lastImage, caption: 'A: ' + overrideList().filter((o) => !o.startsWith('render.')).join(' ') };
    if ($('mode').value === 'current') $('mode').value = 'side';
    applyMode();
  });
  $('reference').addEventListener('click', async () => {
    try {
      const answer = await api('/api/reference', config());
      referenceJob = answer.job.id;
      referenceFor = scene + '|' + overrideList().filter((o) => !o.startsWith('sss.') && !o.startsWith('tone_map.')).join('|');
      $('mode').value = 'difference';
      applyMode();
      followJob(referenceJob, false);
    } catch (e) { showError(e.message); }
  });
  $('cancel').addEventListener('click', async () => {
    try { await api('/api/job/cancel', { id: $('cancel').dataset.job }); } catch (e) { showError(e.message); }
  });
  $('export').addEventListener('click', async () => {
    const request = Object.assign({ name: $('export-name').value }, config());
    try {
      let answer;
      try {
        answer = await api('/api/export', request);
      } catch (e) {
        // Files of that name exist: replaced only when the user says so.
        if (e.status !== 409 || !e.data || !e.data.exists) throw e;
        if (!confirm('Replace ' + e.data.exists.join(' and ') + '?')) { showError(e.message); return; }
        answer = await api('/api/export', Object.assign({ overwrite: true }, request));
      }
      $('export-result').textContent = `${answer.scene_file}\n${answer.include_file}\n\n${answer.command}\n\n${answer.include_text}`;
      $('export-result').hidden = false;
      showError('');
    } catch (e) { showError(e.message); }
  });
  $('open').addEventListener('click', async () => {
    const [set, id] = $('stimulus').value.split(/\|(.*)/s);
    try {
      const answer = await api('/api/open?set=' + encodeURIComponent(set) + '&id=' + encodeURIComponent(id));
      scene = answer.scene;
      $('scene').value = scene;
      overrides.clear();
      for (const o of answer.overrides) { const i = o.indexOf('='); overrides.set(o.slice(0, i), o.slice(i + 1)); }
      resolved = null;
      schedule();
    } catch (e) { showError(e.message); }
  });
  // Orbit: drag on the image turns the camera (yaw, pitch), one degree per two pixels.
  let drag = null;
  $('image').addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY, yaw: Number(valueAt('camera.yaw_deg') || 0), pitch: Number(valueAt('camera.pitch_deg') || 0) };
    $('image').setPointerCapture(e.pointerId);
  });
  $('image').addEventListener('pointermove', (e) => {
    if (!drag) return;
    let yaw = drag.yaw - (e.clientX - drag.x) / 2;
    yaw = ((yaw + 180) % 360 + 360) % 360 - 180;
    const pitch = Math.max(-89, Math.min(89, drag.pitch + (e.clientY - drag.y) / 2));
    overrides.set('camera.yaw_deg', String(rounded(yaw)));
    setOverride('camera.pitch_deg', String(rounded(pitch)));
  });
  $('image').addEventListener('pointerup', () => { drag = null; });
  schedule();
}

start();
