// skinlab participant page: consent → instructions → practice → trials (2AFC) → completion code.
// Every answer is sent to the server and only counted once the server has committed it; a failed send is
// retried with the same body (the server treats a re-send as harmless). After joining, the participant's token is
// kept in the address's fragment (#p=…, which a browser never sends to a server) and only ever sent in request
// bodies or the X-Skinlab-Token header: reloading or reopening that address resumes at the first unanswered trial.
// Online studies: the recruitment platform's URL parameters are forwarded when joining (the same platform id resumes
// with the join key this browser keeps, or with the platform's session id), the optional card calibration and the viewing conditions
// are reported when a session starts (the server refuses one that misses the design's requirements), every
// answer says whether the page was hidden or lost the focus while the trial was shown, and the end may redirect
// to the platform's completion URL.
'use strict';

const params = new URLSearchParams(location.search);
let token = new URLSearchParams(location.hash.slice(1)).get('p');
if (params.has('p')) {
  // An older ?p= link: its token moves into the fragment, out of every later request's URL.
  token = token || params.get('p');
  params.delete('p');
  const query = params.toString();
  history.replaceState(null, '', location.pathname + (query ? '?' + query : '') + '#p=' + encodeURIComponent(token));
}
let study = null;       // /api/study
let session = null;     // session id
let state = null;       // last participant state from the server
let shownAt = 0;        // performance.now() when the current pair appeared
let accepting = false;  // true while a trial waits for an answer
let breakShownAt = -1;  // answered count at which the last break was shown
let cardWidth = null;   // CSS px of the calibrated card (null: no calibration)
let trialHidden = false; // the page was hidden while the current trial was shown
let trialBlurred = false; // the window lost the focus while the current trial was shown

const $ = (id) => document.getElementById(id);
// CSS px between and around the images, above them (the question and practice label) and below them (the key
// hint): the server's figures (GET /api/study "stage"), the same ones `study create` checked the design with.
let MARGIN = 16;
let TOP = 64;
let BOTTOM = 36;

function showScreen(html) {
  $('stage').hidden = true;
  $('screen').hidden = false;
  $('screen').innerHTML = html;
}

function escapeHtml(text) {
  return String(text).replace(/[&<>"']/g, (c) => ({'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;'}[c]));
}

function notice(text) {
  $('notice').textContent = text || '';
  $('notice').hidden = !text;
}

function viewport() {
  return {viewport_width: window.innerWidth, viewport_height: window.innerHeight,
          device_pixel_ratio: window.devicePixelRatio || 1};
}

function isFullscreen() {
  return !!(document.fullscreenElement || document.webkitFullscreenElement);
}

// Reported when a session starts: the screen (CSS px), colour depth, full screen, pointer, and the calibration.
function viewingConditions() {
  const conditions = Object.assign(viewport(), {
    screen_width: screen.width, screen_height: screen.height, colour_depth: screen.colorDepth || 0,
    fullscreen: isFullscreen(), pointer_fine: window.matchMedia('(pointer: fine)').matches,
    touch_points: navigator.maxTouchPoints || 0});
  if (cardWidth !== null) conditions.card_width = cardWidth;
  return conditions;
}

document.addEventListener('visibilitychange', () => { if (document.hidden) trialHidden = true; });
window.addEventListener('blur', () => { trialBlurred = true; });

async function api(method, path, body, headers) {
  const init = {method, headers: Object.assign({}, headers)};
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  const response = await fetch(path, init);
  let data = null;
  try { data = await response.json(); } catch (e) { data = {error: 'unreadable answer'}; }
  if (!response.ok) {
    const error = new Error(data && data.error ? data.error : 'HTTP ' + response.status);
    error.status = response.status;
    throw error;
  }
  return data;
}

// Retries network failures, server errors (5xx) and 429 (too many joins or connections from this address) with
// back-off; other client errors (4xx) are final.
async function apiRetrying(method, path, body, headers) {
  for (let attempt = 0; ; attempt++) {
    try {
      const data = await api(method, path, body, headers);
      notice('');
      return data;
    } catch (e) {
      if (e.status && e.status < 500 && e.status !== 429) throw e;
      if (attempt >= 60) throw e; // about 5 minutes
      notice('Connection to the study server lost — retrying…');
      await new Promise((r) => setTimeout(r, Math.min(500 * (attempt + 1), 5000)));
    }
  }
}

function waitForKeyOrClick(keys) {
  return new Promise((resolve) => {
    const onKey = (e) => { if (keys.includes(e.key)) { cleanup(); e.preventDefault(); resolve(); } };
    const button = document.querySelector('#screen button');
    const onClick = () => { cleanup(); resolve(); };
    function cleanup() { window.removeEventListener('keydown', onKey); if (button) button.removeEventListener('click', onClick); }
    window.addEventListener('keydown', onKey);
    if (button) button.addEventListener('click', onClick);
  });
}

// The recruitment platform's parameters present in the link.
function recruitmentParameters() {
  const found = {};
  for (const name of study.recruitment.parameters) if (params.has(name)) found[name] = params.get(name);
  return found;
}

// The credit-card match (ISO/IEC 7810 ID-1): resize the outline until it covers a real card held to the screen.
async function calibrate() {
  const ratio = study.display.card_height_mm / study.display.card_width_mm;
  let width = Math.round(study.display.card_width_mm / 25.4 * 96); // the CSS inch as a first guess
  showScreen('<h1>Screen size</h1><p class="message">Hold a credit card (or any card of that size) flat against ' +
    'the screen, over the outline. Make the outline exactly as large as the card with ← and → (hold Shift for ' +
    'bigger steps) or the slider, then press <b>Enter</b>.' +
    (study.display.viewing_distance_mm > 0 ? '\nDuring the study, please sit about ' +
      Math.round(study.display.viewing_distance_mm / 10) + ' cm from the screen.' : '') +
    '</p><input id="card-size" type="range" min="100" max="1200" step="1"><div id="card"></div>' +
    '<button id="card-done">Done</button>');
  const card = $('card');
  const slider = $('card-size');
  const apply = () => {
    card.style.width = width + 'px';
    card.style.height = Math.round(width * ratio * 100) / 100 + 'px';
    slider.value = String(width);
    card.dataset.width = String(width);
  };
  apply();
  await new Promise((resolve) => {
    slider.addEventListener('input', () => { width = Number(slider.value); apply(); });
    const onKey = (e) => {
      if (e.key === 'ArrowLeft' || e.key === 'ArrowRight') {
        e.preventDefault();
        width = Math.min(1200, Math.max(100, width + (e.key === 'ArrowRight' ? 1 : -1) * (e.shiftKey ? 10 : 1)));
        apply();
      } else if (e.key === 'Enter') {
        e.preventDefault();
        done();
      }
    };
    function done() { window.removeEventListener('keydown', onKey); resolve(); }
    window.addEventListener('keydown', onKey);
    $('card-done').addEventListener('click', done);
  });
  cardWidth = width;
}

// Starts a session; a session that misses the study's requirements is refused by the server, with the reason.
async function startSession() {
  for (;;) {
    try {
      return await apiRetrying('POST', '/api/session', Object.assign({token}, viewingConditions()));
    } catch (e) {
      if (e.status !== 403) throw e;
      document.body.dataset.refused = 'true';
      showScreen('<h1>This study cannot start yet</h1><p class="message" id="refusal">' + escapeHtml(e.message) +
        '</p><p>Change this and press <b>Enter</b> or the button to try again.</p><button>Try again</button>');
      await waitForKeyOrClick(['Enter']);
      if (study.requirements.fullscreen && !isFullscreen() && document.documentElement.requestFullscreen) {
        try { await document.documentElement.requestFullscreen(); } catch (ignored) { /* the message stays */ }
      }
    }
  }
}

async function start() {
  study = await apiRetrying('GET', '/api/study');
  document.title = study.title;
  const platform = study.recruitment.platform;
  if (!token && platform === 'mturk' && params.get('assignmentId') === 'ASSIGNMENT_ID_NOT_AVAILABLE') {
    // MTurk's preview of the HIT: the instructions only; nobody joins before accepting it.
    document.body.dataset.preview = 'true';
    showScreen('<h1>' + escapeHtml(study.title) + '</h1><p class="message">' +
      escapeHtml(study.instructions || 'Each trial shows two images side by side. ' + study.question) +
      '</p><p><b>Accept the HIT to take part.</b></p>');
    return;
  }
  if (!token && platform !== 'none' && !params.has(study.recruitment.id_parameter)) {
    showScreen('<h1>' + escapeHtml(study.title) + '</h1><p class="message">Please open this study from its link on ' +
      escapeHtml(platform) + ' (the link carries your participant id).</p>');
    return;
  }
  await ensureStudyFits();
  if (!token) {
    showScreen('<h1>' + escapeHtml(study.title) + '</h1><p class="message">' +
      escapeHtml(study.consent || 'This study shows you pairs of images and asks which one matches a question. ' +
        'It takes about 10–20 minutes. Your answers are stored anonymously with a participant number. ' +
        'You can stop at any time by closing this page.') +
      '</p><p>Press <b>Enter</b> or the button to agree and continue.</p><button id="agree">I agree</button>');
    await waitForKeyOrClick(['Enter']);
    // The join key (a secret of this browser) makes a retried join (answer lost in transit) return the same
    // participant. A platform participant's is kept for good (per platform id): it is what lets this browser
    // resume later, as the platform id alone does not.
    const storage = platform !== 'none' ? localStorage : sessionStorage;
    const keyName = 'skinlab-join-key' + (platform !== 'none' ? ':' + params.get(study.recruitment.id_parameter) : '');
    let joinKey = storage.getItem(keyName);
    if (!joinKey) {
      const bytes = new Uint8Array(16);
      crypto.getRandomValues(bytes);
      joinKey = Array.from(bytes, (b) => b.toString(16).padStart(2, '0')).join('');
      storage.setItem(keyName, joinKey);
    }
    const join = {join_key: joinKey};
    if (platform !== 'none') join.recruitment = recruitmentParameters();
    let joined;
    try {
      joined = await apiRetrying('POST', '/api/join', join);
    } catch (e) {
      if (e.status !== 409 || platform === 'none') throw e;
      // This platform id started the study elsewhere (another browser, another link).
      document.body.dataset.refused = 'true';
      showScreen('<h1>' + escapeHtml(study.title) + '</h1><p class="message" id="refusal">' + escapeHtml(e.message) +
        '</p>');
      return;
    }
    token = joined.token;
    if (platform === 'none') sessionStorage.removeItem(keyName); // a later visit to the bare link is a new participant
    // This address now identifies the participant (in its fragment): reloading or reopening it resumes.
    history.replaceState(null, '', location.pathname + location.search + '#p=' + encodeURIComponent(token));
  }
  if (study.display.calibrate) await calibrate();
  state = await startSession();
  session = state.session;
  if (state.completed) return finish();
  if (state.answered === 0 && state.practice_answered === 0) {
    showScreen('<h1>Instructions</h1><p class="message">' +
      escapeHtml(study.instructions || 'Each trial shows two images side by side. ' + study.question +
        '\nAnswer with the ← (left) or → (right) arrow key, or click the image. There are no right or wrong answers; ' +
        'go with your first impression. The first trials are practice.') +
      '</p><p>Press <b>Space</b> to start.</p><button>Start</button>');
    await waitForKeyOrClick([' ', 'Enter']);
  } else {
    showScreen('<h1>Welcome back</h1><p>You will continue where you stopped.</p>' +
      '<p>Press <b>Space</b> to continue.</p><button>Continue</button>');
    await waitForKeyOrClick([' ', 'Enter']);
  }
  await runTrials();
}

function updateProgress() {
  $('bar').hidden = false;
  const total = state.total + state.practice_total;
  const done = state.answered + state.practice_answered;
  $('bar-fill').style.width = (total ? (100 * done / total) : 100) + '%';
}

// CSS pixels needed to show images of w × h device pixels side by side (and a reference refH tall above them) at
// one image pixel per device pixel.
function needed(w, h, refH) {
  const dpr = window.devicePixelRatio || 1;
  return {needW: Math.ceil(w / dpr + 3 * MARGIN), needH: Math.ceil((h + refH) / dpr + TOP + BOTTOM + (refH ? MARGIN : 0))};
}

// Layout in device pixels, snapped so every image's top-left corner is on a whole device pixel.
function layout(trial) {
  const dpr = window.devicePixelRatio || 1;
  const w = trial.left.width + trial.right.width;
  const h = Math.max(trial.left.height, trial.right.height);
  const refH = trial.reference ? trial.reference.height : 0;
  const {needW, needH} = needed(w, h, refH);
  if (window.innerWidth < needW || window.innerHeight < needH) return {tooSmall: true, needW, needH};
  const snap = (cssPx) => Math.round(cssPx * dpr) / dpr;
  const top = snap(TOP + (trial.reference ? refH / dpr + MARGIN : 0) +
                   (window.innerHeight - needH) / 2);
  const gap = MARGIN;
  const left = snap((window.innerWidth - (w / dpr + gap)) / 2);
  const place = (element, side, x, y) => {
    element.style.left = x + 'px';
    element.style.top = y + 'px';
    element.style.width = side.width / dpr + 'px';
    element.style.height = side.height / dpr + 'px';
  };
  return {tooSmall: false, apply() {
    place($('left'), trial.left, left, top);
    place($('right'), trial.right, snap(left + trial.left.width / dpr + gap), top);
    if (trial.reference) place($('reference'), trial.reference,
      snap((window.innerWidth - trial.reference.width / dpr) / 2), snap(top - MARGIN - refH / dpr));
  }};
}

function fillPanel(element, side) {
  element.innerHTML = '';
  element.classList.toggle('blank', !!side.blank);
  if (!side.blank) {
    const img = document.createElement('img');
    img.src = side.url;
    img.alt = '';
    img.draggable = false;
    element.appendChild(img);
  }
}

function imagesLoaded() {
  const images = Array.from(document.querySelectorAll('#stage img'));
  return Promise.all(images.map((img) => img.complete ? Promise.resolve() :
    new Promise((resolve) => { img.onload = resolve; img.onerror = resolve; })));
}

function showTooSmall(l) {
  document.body.dataset.tooSmall = l.needW + 'x' + l.needH;
  showScreen('<h1>The window is too small</h1><p class="message">The images are shown at their exact pixel size. ' +
    'Please enlarge the window (or use full screen, or reset the browser zoom to 100%) to at least ' +
    l.needW + ' × ' + l.needH + ' CSS pixels (now ' + window.innerWidth + ' × ' + window.innerHeight + '). ' +
    'The study continues by itself once the window is large enough.</p>');
}

async function ensureWindowLargeEnough(trial) {
  for (;;) {
    const l = layout(trial);
    if (!l.tooSmall) { delete document.body.dataset.tooSmall; return l; }
    showTooSmall(l);
    await new Promise((resolve) => window.addEventListener('resize', resolve, {once: true}));
  }
}

// Before consent (and before joining): the largest trial of the study must fit, so nobody joins, or does any
// work, in a window too small to take part.
async function ensureStudyFits() {
  const stage = study.stage;
  if (!stage) return;
  MARGIN = stage.margin; TOP = stage.top; BOTTOM = stage.bottom;
  for (;;) {
    const l = needed(stage.pair_width, stage.pair_height, stage.reference_height);
    if (window.innerWidth >= l.needW && window.innerHeight >= l.needH) { delete document.body.dataset.tooSmall; return; }
    showTooSmall(l);
    await new Promise((resolve) => window.addEventListener('resize', resolve, {once: true}));
  }
}

function waitForAnswer() {
  return new Promise((resolve) => {
    const onKey = (e) => {
      if (!accepting || e.repeat) return;
      if (e.key === 'ArrowLeft' || e.key === 'ArrowRight') {
        e.preventDefault();
        cleanup();
        resolve(e.key === 'ArrowLeft' ? 'left' : 'right');
      }
    };
    const onClick = (e) => {
      if (!accepting) return;
      cleanup();
      resolve(e.currentTarget.dataset.side);
    };
    function cleanup() {
      accepting = false;
      window.removeEventListener('keydown', onKey);
      $('left').removeEventListener('click', onClick);
      $('right').removeEventListener('click', onClick);
    }
    window.addEventListener('keydown', onKey);
    $('left').addEventListener('click', onClick);
    $('right').addEventListener('click', onClick);
  });
}

async function runTrials() {
  let wasPractice = state.trial && state.trial.practice;
  while (!state.completed) {
    const trial = state.trial;
    if (wasPractice && !trial.practice) {
      showScreen('<h1>Practice done</h1><p>The real trials start now. Same task.</p>' +
        '<p>Press <b>Space</b> to continue.</p><button>Continue</button>');
      await waitForKeyOrClick([' ', 'Enter']);
    }
    wasPractice = trial.practice;
    if (!trial.practice && study.break_every > 0 && state.answered > 0 && state.answered % study.break_every === 0 &&
        breakShownAt !== state.answered) {
      breakShownAt = state.answered;
      showScreen('<h1>Short break</h1><p>' + state.answered + ' of ' + state.total +
        ' done. Rest your eyes for a moment.</p><p>Press <b>Space</b> to continue.</p><button>Continue</button>');
      await waitForKeyOrClick([' ', 'Enter']);
    }
    const placement = await ensureWindowLargeEnough(trial);
    $('screen').hidden = true;
    $('stage').hidden = false;
    $('stage').style.visibility = 'hidden';
    $('question').textContent = study.question;
    $('practice-label').hidden = !trial.practice;
    fillPanel($('left'), trial.left);
    fillPanel($('right'), trial.right);
    $('reference').hidden = !trial.reference;
    if (trial.reference) fillPanel($('reference'), trial.reference);
    placement.apply();
    updateProgress();
    await imagesLoaded();
    $('stage').style.visibility = 'visible';
    document.body.dataset.trial = String(trial.id);  // for automated checks
    trialHidden = document.hidden;
    trialBlurred = false;
    shownAt = performance.now();
    accepting = true;
    const side = await waitForAnswer();
    const responseMs = performance.now() - shownAt;
    document.body.classList.add('busy');
    try {
      state = await apiRetrying('POST', '/api/response', Object.assign({
        token, session, trial: trial.id, side, response_ms: Math.round(responseMs * 10) / 10,
        client_time: new Date().toISOString(), page_hidden: trialHidden, focus_lost: trialBlurred,
        fullscreen: isFullscreen()}, viewport()));
    } catch (e) {
      if (e.status === 409) {
        // Answered elsewhere (another tab): continue from the server's state.
        state = await apiRetrying('GET', '/api/state', undefined, {'X-Skinlab-Token': token});
      } else {
        throw e;
      }
    } finally {
      document.body.classList.remove('busy');
    }
  }
  finish();
}

function finish() {
  $('bar').hidden = false;
  $('bar-fill').style.width = '100%';
  document.body.dataset.completed = 'true';
  showScreen('<h1>Thank you!</h1><p>You have completed the study. Your completion code is:</p>' +
    '<p class="code" id="completion-code">' + escapeHtml(state.completion_code || '') + '</p>' +
    (state.completion_url ? '<p>Returning you to the recruitment site… (<a id="completion-link" href="' +
      escapeHtml(state.completion_url) + '">continue</a>)</p>' : '<p>You can close this page now.</p>'));
  if (state.completion_url) {
    document.body.dataset.redirect = state.completion_url;
    setTimeout(() => location.assign(state.completion_url), 1500);
  }
}

start().catch((e) => {
  showScreen('<h1>Something went wrong</h1><p class="message">' + escapeHtml(e.message) +
    '</p><p>Reload the page to try again; your answers so far are saved.</p>');
});
