// Browser test of an online study: Debian's headless Chromium driven by playwright-core arrives from a Prolific
// link (?PROLIFIC_PID=...&STUDY_ID=...&SESSION_ID=...), matches the calibration card, answers two trials (the page
// hidden during the second: another tab brought to the front, and where headless Chromium keeps every tab visible,
// as Debian 12's does, document.hidden = true with a visibilitychange event dispatched to the page), leaves, comes back in a fresh browser with the same link and resumes where it stopped,
// loses the focus during one more trial, finishes, and is redirected to the completion URL (served here by a
// stand-in for the platform). A third browser with the same PROLIFIC_PID (upper case) and another SESSION_ID is
// refused with a page saying why. The export must hold one participant with the platform ids, the session's viewing
// conditions and pixels per degree, and exactly the hidden and unfocused trials flagged.
// Usage: node online_session.test.mjs /path/to/skinlab     Exit 0 pass, 1 fail, 77 skip.
import { spawnSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { encodePng, CHROMIUM, FLAGS, loadPlaywright, serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node online_session.test.mjs SKINLAB_CLI'); process.exit(1); }
const chromium = await loadPlaywright(here);

let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

// --- a tiny stimulus set: one block, three methods, flat colours ---
function solidPng(width, height, rgb) {
  const pixels = Buffer.alloc(width * height * 3);
  for (let i = 0; i < width * height; i++) rgb.forEach((v, k) => { pixels[i * 3 + k] = v; });
  return encodePng(width, height, pixels);
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-online-'));
const W = 64, H = 48;
fs.mkdirSync(path.join(work, 'stimuli/png'), { recursive: true });
const manifest = { format: 'skinlab-stimuli', version: 1, set: 'online-test', spec_sha256: '0'.repeat(64),
  renderer: { gl_renderer: 'none', gl_version: '', skinlab_version: '' }, stimuli: [] };
[['reference-like', [200, 60, 60]], ['separable', [60, 160, 60]], ['artistic', [60, 60, 200]]].forEach(([method, rgb]) => {
  const png = solidPng(W, H, rgb);
  const id = 'head-mid-' + method;
  fs.writeFileSync(path.join(work, 'stimuli/png', id + '.png'), png);
  manifest.stimuli.push({ id, files: { exr: 'exr/' + id + '.exr', png: 'png/' + id + '.png' },
    sha256: { exr: '0'.repeat(64), png: createHash('sha256').update(png).digest('hex') },
    factors: { scene: 'builtin:head', view: 'mid', method }, block: 'builtin:head/mid', reference: false,
    width: W, height: H, resolved: {}, timings_ms: {} });
});
fs.writeFileSync(path.join(work, 'stimuli/manifest.json'), JSON.stringify(manifest, null, 2));

// --- the platform's completion page (a stand-in for app.prolific.com) ---
const completions = [];
const platform = http.createServer((req, res) => {
  if (req.url !== '/favicon.ico') completions.push(req.url);
  res.writeHead(200, { 'Content-Type': 'text/html' });
  res.end('<!doctype html><title>Submission complete</title><p id="platform-done">Complete</p>');
});
await new Promise((resolve) => platform.listen(0, '127.0.0.1', resolve));
const platformPort = platform.address().port;

const CODE = 'C1ABCDEF';
fs.writeFileSync(path.join(work, 'design.toml'),
  'title = "Online browser test"\nquestion = "Which looks more like real skin?"\nseed = 7\nrepetitions = 1\n' +
  'break_every = 0\n[practice]\ntrials = 1\n[catch]\nblank = 1\n' +
  `[recruitment]\nplatform = "prolific"\ncompletion_url = "http://127.0.0.1:${platformPort}/complete?cc={code}"\n` +
  `completion_code = "${CODE}"\n[display]\ncalibrate = true\nviewing_distance_mm = 600\n`);
const database = path.join(work, 'study.db');
const created = spawnSync(cli, ['study', 'create', '--stimuli', path.join(work, 'stimuli'), '--design',
  path.join(work, 'design.toml'), '-o', database], { encoding: 'utf8' });
if (created.status !== 0) { console.error(created.stderr); process.exit(1); }
const TRIALS = 5; // 1 practice + 3 pairs + 1 catch

const { process: server, port } = await serve(cli, database, ['--token', 'browser-researcher-token-0123']);
const PID = '5f8a1b2c3d4e5f6a7b8c9d0e', STUDY_ID = '60aa1b2c3d4e5f6a7b8c9d11', SESSION_ID = '60bb1b2c3d4e5f6a7b8c9d22';
const link = `http://127.0.0.1:${port}/?PROLIFIC_PID=${PID}&STUDY_ID=${STUDY_ID}&SESSION_ID=${SESSION_ID}`;

// The next thing to act on: a new trial, a screen with a title, the end, or the platform's page.
async function nextState(page, lastTrial) {
  const handle = await page.waitForFunction((last) => {
    if (document.getElementById('platform-done')) return 'platform';
    if (document.body.dataset.completed === 'true') return 'done';
    const stage = document.getElementById('stage');
    const screen = document.getElementById('screen');
    if (!stage.hidden && stage.style.visibility === 'visible' && document.body.dataset.trial !== last &&
        !document.body.classList.contains('busy')) return 'trial';
    if (!screen.hidden && screen.querySelector('h1')) return 'screen:' + screen.querySelector('h1').textContent;
    return false;
  }, lastTrial, { timeout: 20000, polling: 50 });
  return handle.jsonValue();
}

// One visit from the Prolific link in a fresh browser profile: answers up to `answerCount` trials. `disturb(n)` says
// what happens while the n-th trial of this visit is shown: 'hide' (another tab in front) or 'blur'.
async function visit({ name, answerCount, disturb, expectWelcomeBack }) {
  const profile = fs.mkdtempSync(path.join(work, 'profile-'));
  const context = await chromium.launchPersistentContext(profile, { executablePath: CHROMIUM, headless: true, args: FLAGS,
    viewport: { width: 1000, height: 700 } });
  const page = context.pages()[0] || await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(link);
  const answered = [];
  let lastTrial = '', sawWelcomeBack = false, calibrated = false, redirected = false, code = '';
  for (let step = 0; step < 40; step++) {
    const state = await nextState(page, lastTrial);
    if (state === 'platform') { redirected = true; break; }
    if (state === 'done') {
      code = await page.textContent('#completion-code');
      await page.waitForURL(/\/complete\?cc=/, { timeout: 10000 });
      continue;
    }
    if (state.startsWith('screen:')) {
      const title = state.slice(7);
      if (title === 'Screen size') {
        // The card outline starts at the CSS inch guess; make it 40 CSS px wider, as a participant would.
        for (let k = 0; k < 4; k++) await page.keyboard.press('Shift+ArrowRight');
        calibrated = Number(await page.getAttribute('#card', 'data-width'));
      }
      if (title === 'Welcome back') sawWelcomeBack = true;
      await page.keyboard.press(title === 'Instructions' || title === 'Welcome back' ? 'Space' : 'Enter');
      await page.waitForFunction((t) => document.getElementById('screen').hidden ||
        document.querySelector('#screen h1')?.textContent !== t, title);
      continue;
    }
    if (answered.length === answerCount) break;
    const trial = await page.evaluate(() => document.body.dataset.trial);
    const what = disturb(answered.length + 1);
    if (what === 'hide') {
      // Another tab brought to the front hides this page (visibilitychange); then back.
      const other = await context.newPage();
      await other.bringToFront();
      const hidden = await page.evaluate(() => document.hidden);
      console.log(`${name}: page hidden by ${hidden ? 'another tab in front' : 'a dispatched visibilitychange'}`);
      if (!hidden) {
        // Some headless builds keep every tab visible: hide the page the way a browser does.
        await page.evaluate(() => {
          Object.defineProperty(document, 'hidden', { configurable: true, get: () => true });
          document.dispatchEvent(new Event('visibilitychange'));
          delete document.hidden;
        });
      }
      await other.close();
      await page.bringToFront();
    } else if (what === 'blur') {
      await page.evaluate(() => window.dispatchEvent(new Event('blur')));
    }
    answered.push({ trial: Number(trial) % 4294967296, disturbed: what });
    await page.keyboard.press('ArrowLeft');
    lastTrial = trial;
  }
  if (answered.length === answerCount && answerCount < TRIALS) {
    // Leave mid-study once the last answer is stored.
    await page.waitForFunction(() => !document.body.classList.contains('busy'));
  }
  check(pageErrors.length === 0, `${name}: page errors: ${pageErrors.join('; ')}`);
  check(calibrated > 0, `${name}: no calibration screen`);
  if (expectWelcomeBack) check(sawWelcomeBack, `${name}: the repeat visit did not resume ("Welcome back")`);
  const url = page.url();
  await context.close();
  return { answered, redirected, code, url, calibrated };
}

// Someone else with the participant's PROLIFIC_PID (in upper case) but not their browser or their SESSION_ID: refused
// with a page saying why, never given the participation.
async function takeover() {
  const profile = fs.mkdtempSync(path.join(work, 'profile-'));
  const context = await chromium.launchPersistentContext(profile, { executablePath: CHROMIUM, headless: true, args: FLAGS,
    viewport: { width: 1000, height: 700 } });
  const page = context.pages()[0] || await context.newPage();
  await page.goto(`http://127.0.0.1:${port}/?PROLIFIC_PID=${PID.toUpperCase()}&STUDY_ID=${STUDY_ID}` +
    '&SESSION_ID=60cc1b2c3d4e5f6a7b8c9d33');
  await page.waitForSelector('#agree');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.body.dataset.refused === 'true', null, { timeout: 20000 });
  const text = await page.textContent('#refusal');
  const trialShown = await page.evaluate(() => document.body.dataset.trial !== undefined);
  await context.close();
  return { text, trialShown };
}

let exitCode = 1;
try {
  const first = await visit({ name: 'first visit', answerCount: 2, disturb: (n) => (n === 2 ? 'hide' : null) });
  const second = await visit({ name: 'repeat visit', answerCount: TRIALS, expectWelcomeBack: true,
    disturb: (n) => (n === 1 ? 'blur' : null) });
  const stranger = await takeover();
  check(/already started this study/.test(stranger.text) && !stranger.trialShown,
    `the same PROLIFIC_PID without the participant's browser or SESSION_ID was not refused: "${stranger.text}"`);
  check(first.answered.length === 2, `first visit answered ${first.answered.length}`);
  check(second.answered.length === TRIALS - 2, `repeat visit answered ${second.answered.length}, expected ${TRIALS - 2}`);
  check(second.code === CODE, `completion code shown "${second.code}", expected ${CODE}`);
  check(second.redirected && /\/complete\?cc=C1ABCDEF$/.test(second.url), `not redirected to the completion URL (${second.url})`);
  check(completions.length === 1 && completions[0] === `/complete?cc=${CODE}`, `platform saw ${JSON.stringify(completions)}`);

  const exported = spawnSync(cli, ['study', 'export', database, '--format', 'json', '--include-session-ids'],
    { encoding: 'utf8' });
  check(exported.status === 0, 'export failed: ' + exported.stderr);
  const data = JSON.parse(exported.stdout);
  check(data.participants.length === 1, `${data.participants.length} participants, expected 1 (the same PROLIFIC_PID)`);
  const ids = data.participants[0].recruitment || {};
  check(ids.external_id === PID && ids.external_study_id === STUDY_ID && ids.external_session_id === SESSION_ID,
    `stored ids ${JSON.stringify(ids)}`);
  check(data.responses.length === TRIALS, `stored ${data.responses.length} responses, expected ${TRIALS}`);
  const expectFlag = new Map([...first.answered, ...second.answered].map((a) => [a.trial, a.disturbed]));
  for (const r of data.responses) {
    const disturbed = expectFlag.get(r.trial_id);
    check(disturbed !== undefined, `stored trial ${r.trial_id} was not answered in the browser`);
    check(r.flagged === (disturbed ? 1 : 0), `trial ${r.trial_id}: flagged ${r.flagged}, page ${disturbed || 'undisturbed'}`);
    check(r.page_hidden === (disturbed === 'hide'), `trial ${r.trial_id}: page_hidden ${r.page_hidden}`);
    // Switching tabs may also take the focus: only the trials left alone must have neither.
    if (disturbed !== 'hide') check(r.focus_lost === (disturbed === 'blur'), `trial ${r.trial_id}: focus_lost ${r.focus_lost}`);
    check(r.recruitment && r.recruitment.external_id === PID, `trial ${r.trial_id}: no external id`);
  }
  check(data.sessions.length === 2, `${data.sessions.length} sessions, expected 2`);
  for (const s of data.sessions) {
    const v = s.viewing;
    check(v && v.screen_width > 0 && v.screen_height > 0 && v.colour_depth > 0, `session ${s.session_id}: viewing ${JSON.stringify(v)}`);
    check(v && v.pixels_per_mm > 0 && Math.abs(v.viewing_distance_mm - 600) < 1e-9, `session ${s.session_id}: calibration`);
    const expectedPpd = 2 * 600 * Math.tan(0.5 * Math.PI / 180) * (first.calibrated * s.device_pixel_ratio / 85.6);
    check(v && Math.abs(v.pixels_per_degree - expectedPpd) < 1e-6, `session ${s.session_id}: ppd ${v && v.pixels_per_degree}, expected ${expectedPpd}`);
  }
  // The participant page never receives a platform id from the server.
  const status = await (await fetch(`http://127.0.0.1:${port}/api/study`)).text();
  check(!status.includes(PID), '/api/study shows a platform id');
  // The researcher's dashboard lists the platform id the stranger tried, with the attempt.
  const board = await chromium.launchPersistentContext(fs.mkdtempSync(path.join(work, 'profile-')),
    { executablePath: CHROMIUM, headless: true, args: FLAGS, viewport: { width: 1000, height: 700 } });
  const dashboard = board.pages()[0] || await board.newPage();
  const dashboardErrors = [];
  dashboard.on('pageerror', (e) => dashboardErrors.push(e.message));
  await dashboard.goto(`http://127.0.0.1:${port}/researcher#token=browser-researcher-token-0123`);
  await dashboard.waitForFunction(() => Number(document.body.dataset.refreshes || 0) >= 1, null, { timeout: 10000 });
  const refusedCount = await dashboard.getAttribute('#refused-ids', 'data-count');
  const refusedText = await dashboard.textContent('#refused-list');
  check(refusedCount === '1' && refusedText.includes(`(prolific ${PID}): 1 refused join from 1 address`),
    `refused platform ids on the dashboard: ${refusedCount} "${refusedText}"`);
  check(dashboardErrors.length === 0, 'dashboard errors: ' + dashboardErrors.join('; '));
  await board.close();
  exitCode = failures === 0 ? 0 : 1;
} catch (e) {
  console.error(e);
} finally {
  server.kill('SIGTERM');
  platform.close();
  try {
    fs.rmSync(work, { recursive: true, force: true, maxRetries: 10, retryDelay: 200 });
  } catch (e) {
    console.error(`warning: could not remove ${work}: ${e.message}`);
  }
}
console.log(exitCode === 0 ? 'PASS: browser online session' : `FAILED (${failures} checks)`);
process.exit(exitCode);
