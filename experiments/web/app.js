// skinlab participant page: consent → instructions → practice → trials (2AFC) → completion code.
// Every answer is sent to the server and only counted once the server has committed it; a failed send is
// retried with the same body (the server treats a re-send as harmless). Reloading the page with the same ?p=
// link resumes at the first unanswered trial.
'use strict';

const params = new URLSearchParams(location.search);
let token = params.get('p');
let study = null;       // /api/study
let session = null;     // session id
let state = null;       // last participant state from the server
let shownAt = 0;        // performance.now() when the current pair appeared
let accepting = false;  // true while a trial waits for an answer
let breakShownAt = -1;  // answered count at which the last break was shown

const $ = (id) => document.getElementById(id);
const MARGIN = 16;      // CSS px between and around the images
const TOP = 64;         // CSS px reserved for the question (and practice label)
const BOTTOM = 36;      // CSS px reserved for the key hint

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

async function api(method, path, body) {
  const init = {method, headers: {}};
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
async function apiRetrying(method, path, body) {
  for (let attempt = 0; ; attempt++) {
    try {
      const data = await api(method, path, body);
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

async function start() {
  study = await apiRetrying('GET', '/api/study');
  document.title = study.title;
  if (!token) {
    showScreen('<h1>' + escapeHtml(study.title) + '</h1><p class="message">' +
      escapeHtml(study.consent || 'This study shows you pairs of images and asks which one matches a question. ' +
        'It takes about 10–20 minutes. Your answers are stored anonymously with a participant number. ' +
        'You can stop at any time by closing this page.') +
      '</p><p>Press <b>Enter</b> or the button to agree and continue.</p><button id="agree">I agree</button>');
    await waitForKeyOrClick(['Enter']);
    // The join key makes a retried join (answer lost in transit) return the same participant.
    let joinKey = sessionStorage.getItem('skinlab-join-key');
    if (!joinKey) {
      const bytes = new Uint8Array(16);
      crypto.getRandomValues(bytes);
      joinKey = Array.from(bytes, (b) => b.toString(16).padStart(2, '0')).join('');
      sessionStorage.setItem('skinlab-join-key', joinKey);
    }
    const joined = await apiRetrying('POST', '/api/join', {join_key: joinKey});
    token = joined.token;
    sessionStorage.removeItem('skinlab-join-key'); // a later visit to the bare link is a new participant
    // The link now identifies this participant: reloading or reopening it resumes.
    history.replaceState(null, '', '?p=' + encodeURIComponent(token));
  }
  state = await apiRetrying('POST', '/api/session', Object.assign({token}, viewport()));
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

// Layout in device pixels, snapped so every image's top-left corner is on a whole device pixel.
function layout(trial) {
  const dpr = window.devicePixelRatio || 1;
  const w = trial.left.width + trial.right.width;
  const h = Math.max(trial.left.height, trial.right.height);
  const refH = trial.reference ? trial.reference.height : 0;
  const needW = w / dpr + 3 * MARGIN;
  const needH = (h + refH) / dpr + TOP + BOTTOM + (trial.reference ? MARGIN : 0);
  if (window.innerWidth < needW || window.innerHeight < needH) {
    return {tooSmall: true, needW: Math.ceil(needW), needH: Math.ceil(needH)};
  }
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

async function ensureWindowLargeEnough(trial) {
  for (;;) {
    const l = layout(trial);
    if (!l.tooSmall) return l;
    showScreen('<h1>The window is too small</h1><p class="message">The images are shown at their exact pixel size. ' +
      'Please enlarge the window (or use full screen, or reset the browser zoom to 100%) to at least ' +
      l.needW + ' × ' + l.needH + ' CSS pixels (now ' + window.innerWidth + ' × ' + window.innerHeight + ').</p>');
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
    shownAt = performance.now();
    accepting = true;
    const side = await waitForAnswer();
    const responseMs = performance.now() - shownAt;
    document.body.classList.add('busy');
    try {
      state = await apiRetrying('POST', '/api/response', Object.assign({
        token, session, trial: trial.id, side, response_ms: Math.round(responseMs * 10) / 10,
        client_time: new Date().toISOString()}, viewport()));
    } catch (e) {
      if (e.status === 409) {
        // Answered elsewhere (another tab): continue from the server's state.
        state = await apiRetrying('GET', '/api/state?token=' + encodeURIComponent(token));
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
    '<p>You can close this page now.</p>');
}

start().catch((e) => {
  showScreen('<h1>Something went wrong</h1><p class="message">' + escapeHtml(e.message) +
    '</p><p>Reload the page to try again; your answers so far are saved.</p>');
});
