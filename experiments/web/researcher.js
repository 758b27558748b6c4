// The researcher's dashboard: polls GET /api/researcher/dashboard (token in the Authorization header only) and
// draws participants, catch-trial accuracy, the response-time histogram and the JOD scale with its intervals.
'use strict';

const REFRESH_MS = 3000;
const SVG = 'http://www.w3.org/2000/svg';
let token = '';
let timer = null;

function $(id) { return document.getElementById(id); }
function text(value) { return value === null || value === undefined ? '–' : String(value); }
function fixed(value, digits) { return typeof value === 'number' ? value.toFixed(digits) : '–'; }
function element(tag, attributes, content) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes || {})) e.setAttribute(k, v);
  if (content !== undefined) e.textContent = content;
  return e;
}
function svgElement(tag, attributes, content) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attributes || {})) e.setAttribute(k, String(v));
  if (content !== undefined) e.textContent = content;
  return e;
}

// The token: from #token=... (the fragment never leaves the browser; removed from the address bar at once),
// else from this tab's storage, else typed into the form.
function initialToken() {
  const match = /(?:^#|&)token=([^&]*)/.exec(location.hash);
  if (match) {
    history.replaceState(null, '', location.pathname + location.search);
    return decodeURIComponent(match[1]);
  }
  return sessionStorage.getItem('skinlab-researcher-token') || '';
}

function showLogin(message) {
  $('dashboard').hidden = true;
  $('login').hidden = false;
  $('login-error').hidden = !message;
  $('login-error').textContent = message || '';
  $('updated').textContent = 'Not connected';
  $('token-input').focus();
}

async function refresh() {
  clearTimeout(timer);
  let response;
  try {
    response = await fetch('/api/researcher/dashboard', { headers: { Authorization: 'Bearer ' + token }, cache: 'no-store' });
  } catch (e) {
    $('updated').textContent = 'Server not reachable; retrying';
    timer = setTimeout(refresh, REFRESH_MS);
    return;
  }
  if (response.status === 401 || response.status === 403) {
    sessionStorage.removeItem('skinlab-researcher-token');
    showLogin(response.status === 403 ? 'Wrong researcher token.' : 'The researcher token is required.');
    return;
  }
  if (response.status === 429) {
    $('updated').textContent = 'Too many wrong researcher tokens from this address; retrying in ' +
      (response.headers.get('Retry-After') || '?') + ' s';
    timer = setTimeout(refresh, 1000 * Math.max(REFRESH_MS / 1000, Number(response.headers.get('Retry-After')) || 0));
    return;
  }
  if (!response.ok) {
    $('updated').textContent = 'Server answered ' + response.status + '; retrying';
    timer = setTimeout(refresh, REFRESH_MS);
    return;
  }
  const data = await response.json();
  sessionStorage.setItem('skinlab-researcher-token', token);
  $('login').hidden = true;
  $('dashboard').hidden = false;
  render(data);
  document.body.dataset.refreshes = String(Number(document.body.dataset.refreshes || 0) + 1);
  timer = setTimeout(refresh, REFRESH_MS);
}

function render(data) {
  $('title').textContent = data.study.title || 'Study dashboard';
  $('updated').textContent = 'Updated ' + new Date().toLocaleTimeString() + ' (every ' + REFRESH_MS / 1000 + ' s)';
  const totals = data.totals;
  $('participant-count').textContent = text(totals.participants);
  $('completed-count').textContent = text(totals.completed);
  $('response-count').textContent = text(totals.responses);
  $('catch-accuracy').textContent = totals.catch_accuracy === null ? '–' :
    Math.round(totals.catch_accuracy * 100) + ' % (' + totals.catch_correct + '/' + totals.catch_answered + ')';
  renderParticipants(data.participants);
  renderHistogram(data.response_times);
  renderScale(data.scale);
  renderFlagged(data.flagged_trials);
  renderViewing(data.viewing_conditions);
  renderRefusedIds(data.refused_platform_ids || []);
}

// Platform ids that someone joined with again without the participant's browser or platform link: the participant
// switching browser, or someone else using the id — a participant who writes that their id is "already started"
// may have been squatted (what to do: docs/deployment.md, "Refused platform ids").
function renderRefusedIds(rows) {
  const note = $('refused-ids');
  note.dataset.count = String(rows.length);
  if (!rows.length) {
    note.classList.add('placeholder');
    note.textContent = 'none';
    return;
  }
  note.classList.remove('placeholder');
  const list = element('ul', { id: 'refused-list' });
  list.append(...rows.map((r) => element('li', { 'data-observer': r.observer }, r.observer + ' (' + r.platform + ' ' +
    r.external_id + '): ' + (r.attempts_capped ? 'at least ' : '') + r.attempts + ' refused join' +
    (r.attempts > 1 ? 's' : '') + ' from ' + r.addresses + ' address' + (r.addresses > 1 ? 'es' : '') +
    ', last ' + r.last_attempt_at)));
  note.replaceChildren(document.createTextNode('Joins with a known platform id, refused without the participant\'s ' +
    'browser or platform link. If the id\'s owner reports being refused, this participation may not be theirs: ' +
    'compare its platform session id with the platform\'s submission before paying or analysing it.'), list);
}

function renderFlagged(flagged) {
  const note = $('flagged');
  note.dataset.count = String(flagged.count || 0);
  if (!flagged.recorded) {
    note.textContent = flagged.note;
    return;
  }
  note.classList.remove('placeholder');
  const shown = flagged.trials.slice(0, 50);
  note.replaceChildren(document.createTextNode(flagged.count + ' trial(s) shown while the page was hidden or unfocused' +
    (flagged.count > shown.length ? ' (first ' + shown.length + ')' : '') + (flagged.count ? ':' : '.')));
  if (flagged.count) {
    const list = element('ul', { id: 'flagged-list' });
    list.append(...shown.map((t) => element('li', {}, t.observer + ', trial ' + (t.position + 1) + ' (' + t.block + '): ' +
      [t.page_hidden ? 'hidden' : '', t.focus_lost ? 'focus lost' : ''].filter(Boolean).join(', '))));
    note.append(list);
  }
}

function renderViewing(viewing) {
  const note = $('viewing');
  note.dataset.sessions = String(viewing.sessions ? viewing.sessions.length : 0);
  if (!viewing.recorded) {
    note.textContent = viewing.note;
    return;
  }
  note.classList.remove('placeholder');
  const table = element('table', { id: 'viewing-table' });
  const head = element('tr');
  for (const h of ['participant', 'screen (CSS px)', 'screen (device px)', 'DPR', 'viewport', 'colour', 'full screen', 'px/degree'])
    head.append(element('th', {}, h));
  table.append(head);
  for (const v of viewing.sessions) {
    const row = element('tr', { 'data-observer': v.observer });
    row.append(element('td', {}, v.observer),
      element('td', {}, v.screen_css ? v.screen_css.join(' × ') : '–'),
      element('td', {}, v.screen_px ? v.screen_px.join(' × ') : '–'),
      element('td', { class: 'number' }, fixed(v.device_pixel_ratio, 2)),
      element('td', {}, v.viewport.join(' × ')),
      element('td', { class: 'number' }, v.colour_depth ? v.colour_depth + ' bit' : '–'),
      element('td', {}, v.fullscreen === undefined ? '–' : v.fullscreen ? 'yes' : 'no'),
      element('td', { class: 'number' }, fixed(v.pixels_per_degree, 1)));
    table.append(row);
  }
  note.replaceChildren(table);
}

function renderParticipants(participants) {
  const body = $('participants').querySelector('tbody');
  body.replaceChildren(...participants.map((p) => {
    const row = element('tr', { 'data-observer': p.observer, 'data-answered': p.answered, 'data-total': p.total });
    row.append(element('td', {}, p.observer),
      element('td', { class: 'number' }, p.answered + ' / ' + p.total + (p.completed ? ' ✓' : '')),
      element('td', { class: 'number' }, p.catch_answered ? p.catch_correct + ' / ' + p.catch_answered : '–'),
      element('td', {}, (p.client_address ? p.client_address + (p.address_source === 'forwarded' ? ' (via proxy)' : '') : '–') +
        (p.refused_attempts ? ` · ${p.refused_attempts} refused attempt${p.refused_attempts > 1 ? 's' : ''} with this platform id` : '')),
      element('td', {}, p.last_response_at || '–'));
    return row;
  }));
}

function renderHistogram(times) {
  const svg = $('rt-histogram');
  const width = 640, height = 180, left = 36, bottom = 36, top = 8;
  const bins = times.bins;
  const most = Math.max(1, ...bins.map((b) => b.count));
  const barWidth = (width - left - 8) / bins.length;
  const parts = [svgElement('line', { class: 'axis', x1: left, y1: height - bottom, x2: width - 4, y2: height - bottom })];
  bins.forEach((bin, i) => {
    const h = (height - bottom - top) * bin.count / most;
    const x = left + i * barWidth;
    const bar = svgElement('rect', { class: 'bar', x: x + 1, y: height - bottom - h, width: Math.max(1, barWidth - 2), height: h,
      'data-count': bin.count });
    bar.append(svgElement('title', {}, `${bin.from_ms}–${bin.to_ms === null ? '∞' : bin.to_ms} ms: ${bin.count}`));
    parts.push(bar);
    if (i % 2 === 0) parts.push(svgElement('text', { x: x + 1, y: height - bottom + 14 }, (bin.from_ms / 1000).toString()));
  });
  parts.push(svgElement('text', { x: left, y: height - 4 }, 'seconds from stimulus onset'));
  parts.push(svgElement('text', { x: 2, y: top + 10 }, String(most)));
  svg.replaceChildren(...parts);
  $('rt-note').textContent = times.count === 0 ? 'No answers yet.' :
    `${times.count} answers (${times.excludes} excluded): median ${fixed(times.median_ms, 0)} ms, ` +
    `10th–90th percentile ${fixed(times.p10_ms, 0)}–${fixed(times.p90_ms, 0)} ms`;
}

function renderScale(scale) {
  const container = $('scale');
  if (scale.state !== 'ok') {
    container.replaceChildren();
    $('scale-note').textContent = scale.state === 'computing' ? 'Computing…' :
      scale.state === 'none' ? 'No test answers to scale yet.' : 'Not computed: ' + (scale.message || scale.state);
    return;
  }
  $('scale-note').textContent = `Thurstone Case V, JOD with ${Math.round(scale.level * 100)} % intervals ` +
    `(${scale.bootstrap_samples} bootstrap samples over observers); ${scale.responses} answers, ` +
    `computed ${scale.computed_at} in ${fixed(scale.compute_ms, 0)} ms.` +
    (scale.blocks.some((b) => b.conditions.some((c) => c.interval_fallback)) ?
      ' * : the bootstrap-t interval was not usable; the interval shown is the fallback (percentile ∪ profile likelihood).' : '');
  document.body.dataset.scaleComputedAt = scale.computed_at;
  container.replaceChildren(...scale.blocks.map((block) => {
    const div = element('div', { class: 'scale-block', 'data-block': block.block });
    div.append(element('h3', {}, `${block.block} — ${block.observers} observers, ${block.interval_method}`));
    const table = element('table');
    table.append(element('thead'));
    table.tHead.append(element('tr'));
    for (const h of ['Condition', 'JOD', 'Interval']) table.tHead.rows[0].append(element('th', {}, h));
    const body = element('tbody');
    for (const c of block.conditions) {
      const row = element('tr', { class: 'scale-row', 'data-condition': c.condition, 'data-jod': c.jod });
      if (c.measured === false) row.append(element('td', {}, c.condition),
        element('td', { class: 'not-measured', colspan: '2' }, 'not measured (never compared)'));
      else row.append(element('td', {}, c.condition), element('td', { class: 'number' }, fixed(c.jod, 2)),
        element('td', { class: 'number' }, `[${fixed(c.low, 2)}, ${fixed(c.high, 2)}]` + (c.interval_fallback ? ' *' : '')));
      body.append(row);
    }
    table.append(body);
    div.append(table, scalePlot(block.conditions));
    return div;
  }));
}

// A tick step of 1, 2 or 5 × 10^k giving about five ticks over `span`.
function tickStep(span) {
  const raw = span / 5;
  const power = Math.pow(10, Math.floor(Math.log10(raw)));
  return [1, 2, 5, 10].map((m) => m * power).find((step) => step >= raw);
}

// Each condition's score (dot) and interval (line) on a common JOD axis whose ends are ticks beyond every value.
function scalePlot(conditions) {
  const width = 640, rowHeight = 22, left = 160, right = 20, axisHeight = 34;
  const height = conditions.length * rowHeight + axisHeight;
  const values = conditions.flatMap((c) => [c.low, c.high, c.jod]).filter((v) => typeof v === 'number' && isFinite(v));
  let lo = Math.min(...values, 0), hi = Math.max(...values, 0);
  if (hi - lo < 1e-9) { lo -= 0.5; hi += 0.5; }
  const step = tickStep(hi - lo);
  lo = Math.floor(lo / step - 1e-9) * step;
  hi = Math.ceil(hi / step + 1e-9) * step;
  const x = (v) => left + (width - left - right) * (v - lo) / (hi - lo);
  const svg = svgElement('svg', { width, height, role: 'img', 'aria-label': 'JOD scale with intervals' });
  const axisY = height - axisHeight + 8;
  svg.append(svgElement('line', { class: 'axis', x1: x(lo), y1: axisY, x2: x(hi), y2: axisY }));
  const digits = step < 0.1 ? 2 : step < 1 ? 1 : 0;
  for (let k = 0, v = lo; v <= hi + step / 2; v = lo + (++k) * step) {
    svg.append(svgElement('line', { class: v === 0 || Math.abs(v) < step / 1e6 ? 'axis zero' : 'tick', x1: x(v), y1: 4,
      x2: x(v), y2: axisY + 4 }));
    svg.append(svgElement('text', { class: 'tick-label', x: x(v), y: axisY + 16, 'text-anchor': 'middle' },
      fixed(v, digits)));
  }
  svg.append(svgElement('text', { class: 'tick-label', x: width - right, y: height - 2, 'text-anchor': 'end' }, 'JOD'));
  conditions.forEach((c, i) => {
    const y = 14 + i * rowHeight;
    svg.append(svgElement('text', { x: 4, y: y + 4 }, c.condition));
    if (typeof c.low === 'number' && typeof c.high === 'number')
      svg.append(svgElement('line', { class: 'interval', x1: x(c.low), y1: y, x2: x(c.high), y2: y }));
    if (typeof c.jod === 'number') svg.append(svgElement('circle', { class: 'point', cx: x(c.jod), cy: y, r: 4 }));
  });
  return svg;
}

$('login').addEventListener('submit', (event) => {
  event.preventDefault();
  token = $('token-input').value.trim();
  if (token) refresh();
});

token = initialToken();
if (token) refresh();
else showLogin('');
