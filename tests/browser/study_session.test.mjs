// Browser test of the participant page: Debian's headless Chromium driven by playwright-core completes short
// sessions with the keyboard (one at devicePixelRatio 1 in a window first too small, one with
// --force-device-scale-factor=2), checks that every image is shown at one image pixel per device pixel (layout
// and screenshot pixels), resumes after a reload, and checks the stored rows.
// With "active" as second argument the study is an active design (pairs = "active", test trials planned batch by
// batch while the session runs); the same checks apply.
// Usage: node study_session.test.mjs /path/to/skinlab [active]     Exit 0 pass, 1 fail, 77 skip.
import { spawnSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';
import { encodePng, CHROMIUM, FLAGS, loadPlaywright, serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
const active = process.argv[3] === 'active';
if (!cli || !fs.existsSync(cli)) { console.error('usage: node study_session.test.mjs SKINLAB_CLI'); process.exit(1); }
const chromium = await loadPlaywright(here);

let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

// --- PNG reading (8-bit RGB/RGBA, no interlace; writing: study_fixture.mjs) ---
function decodePng(buffer) {
  let offset = 8, width = 0, height = 0, colourType = 0;
  const idat = [];
  while (offset < buffer.length) {
    const length = buffer.readUInt32BE(offset);
    const type = buffer.toString('ascii', offset + 4, offset + 8);
    const data = buffer.subarray(offset + 8, offset + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4); colourType = data[9];
      if (data[8] !== 8 || data[12] !== 0) throw new Error('unsupported PNG');
    } else if (type === 'IDAT') idat.push(data);
    offset += 12 + length;
  }
  const channels = colourType === 6 ? 4 : colourType === 2 ? 3 : 0;
  if (!channels) throw new Error('unsupported PNG colour type ' + colourType);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    for (let x = 0; x < stride; x++) {
      const value = raw[y * (stride + 1) + 1 + x];
      const a = x >= channels ? out[y * stride + x - channels] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let predicted = 0;
      if (filter === 1) predicted = a;
      else if (filter === 2) predicted = b;
      else if (filter === 3) predicted = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        predicted = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + x] = (value + predicted) & 0xff;
    }
  }
  const rgb = Buffer.alloc(width * height * 3);
  for (let i = 0; i < width * height; i++) for (let k = 0; k < 3; k++) rgb[i * 3 + k] = out[i * channels + k];
  return { width, height, rgb };
}

// --- a tiny stimulus set: one block, three methods, 1-pixel checkerboards (any resampling blurs them) ---
const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-browser-'));
const W = 160, H = 120;
const methods = ['reference-like', 'separable', 'artistic'];
const colours = [[[200, 40, 40], [30, 180, 60]], [[20, 60, 220], [240, 220, 30]], [[250, 250, 250], [10, 10, 10]]];
fs.mkdirSync(path.join(work, 'stimuli/png'), { recursive: true });
const manifest = { format: 'skinlab-stimuli', version: 1, set: 'browser-test', spec_sha256: '0'.repeat(64),
  renderer: { gl_renderer: 'none', gl_version: '', skinlab_version: '' }, stimuli: [] };
methods.forEach((method, m) => {
  const rgb = Buffer.alloc(W * H * 3);
  for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
    const colour = colours[m][(x + y) % 2];
    for (let k = 0; k < 3; k++) rgb[(y * W + x) * 3 + k] = colour[k];
  }
  const png = encodePng(W, H, rgb);
  const id = 'head-mid-' + method;
  fs.writeFileSync(path.join(work, 'stimuli/png', id + '.png'), png);
  manifest.stimuli.push({ id, files: { exr: 'exr/' + id + '.exr', png: 'png/' + id + '.png' },
    sha256: { exr: '0'.repeat(64), png: createHash('sha256').update(png).digest('hex') },
    factors: { scene: 'builtin:head', view: 'mid', method }, block: 'builtin:head/mid', reference: false,
    width: W, height: H, resolved: {}, timings_ms: {} });
});
fs.writeFileSync(path.join(work, 'stimuli/manifest.json'), JSON.stringify(manifest, null, 2));
fs.writeFileSync(path.join(work, 'design.toml'),
  'title = "Browser test"\nquestion = "Which looks more like real skin?"\nseed = 3\nbreak_every = 2\n' +
  (active ? 'pairs = "active"\ntrials_per_participant = 3\n' : 'repetitions = 1\n') +
  '[practice]\ntrials = 1\n[catch]\nblank = 1\n');
const database = path.join(work, 'study.db');
const created = spawnSync(cli, ['study', 'create', '--stimuli', path.join(work, 'stimuli'), '--design',
  path.join(work, 'design.toml'), '-o', database], { encoding: 'utf8' });
if (created.status !== 0) { console.error(created.stderr); process.exit(1); }
const TRIALS = 5; // 1 practice + 3 pairs (active: 3 planned test trials, batches of 2) + 1 catch

// --- the real server ---
const { process: server, port } = await serve(cli, database, ['--token', 'browser-researcher-token-0123']);
const base = `http://127.0.0.1:${port}/`;
const sourceImages = new Map(); // URL → decoded PNG as served
async function served(url) {
  if (!sourceImages.has(url)) sourceImages.set(url, decodePng(Buffer.from(await (await fetch(base + url.slice(1))).arrayBuffer())));
  return sourceImages.get(url);
}

// Checks every image of the current trial: CSS size × dpr = image size, top-left on a whole device pixel, and the
// screenshot of its box equals the served image pixel for pixel.
async function checkOneToOne(page, label) {
  const boxes = await page.evaluate(() => Array.from(document.querySelectorAll('#stage img')).map((img) => {
    const r = img.getBoundingClientRect();
    return { url: img.getAttribute('src'), x: r.left, y: r.top, width: r.width, height: r.height,
      naturalWidth: img.naturalWidth, naturalHeight: img.naturalHeight, dpr: window.devicePixelRatio };
  }));
  check(boxes.length >= 1, `${label}: no image shown`);
  for (const box of boxes) {
    const dpr = box.dpr;
    check(Math.abs(box.width * dpr - box.naturalWidth) < 1e-3 && Math.abs(box.height * dpr - box.naturalHeight) < 1e-3,
      `${label}: ${box.url} is ${box.width}×${box.height} CSS px at dpr ${dpr}, image ${box.naturalWidth}×${box.naturalHeight}`);
    const onGrid = (v) => Math.abs(v * dpr - Math.round(v * dpr)) < 1e-3;
    check(onGrid(box.x) && onGrid(box.y), `${label}: ${box.url} at (${box.x}, ${box.y}) is not on a device pixel`);
    const shot = decodePng(await page.screenshot({ clip: { x: box.x, y: box.y, width: box.width, height: box.height },
      scale: 'device', animations: 'disabled' }));
    const source = await served(box.url);
    check(shot.width === source.width && shot.height === source.height,
      `${label}: screenshot ${shot.width}×${shot.height} for a ${source.width}×${source.height} image`);
    if (shot.width === source.width && shot.height === source.height) {
      let worst = 0;
      for (let i = 0; i < source.rgb.length; i++) worst = Math.max(worst, Math.abs(shot.rgb[i] - source.rgb[i]));
      // A 1-pixel checkerboard resampled by even a fraction of a pixel changes by ~100 levels; 2 allows rounding
      // in colour conversion.
      check(worst <= 2, `${label}: ${box.url} displayed pixels differ from the image by up to ${worst} levels`);
    }
  }
}

// Waits for the next thing to act on: a new trial, a screen with a button, or the end.
async function nextState(page, lastTrial) {
  const handle = await page.waitForFunction((last) => {
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

async function runSession({ name, dpr, launch, resize, reloadAfter }) {
  const profile = fs.mkdtempSync(path.join(work, 'profile-'));
  const context = await chromium.launchPersistentContext(profile, { executablePath: CHROMIUM, headless: true, ...launch });
  const page = context.pages()[0] || await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  const requested = []; // every URL the browser asked for, with the headers that could carry a secret
  context.on('request', (r) => requested.push(r.url() + ' ' + (r.headers().referer || '')));
  await page.goto(base);
  const answers = new Map(); // trial id → side
  let lastTrial = '', reloaded = false, expectAfterReload = null, sawTooSmall = false, sawBreak = false, code = '';
  for (let step = 0; step < 40; step++) {
    const state = await nextState(page, lastTrial);
    if (state === 'done') {
      code = await page.textContent('#completion-code');
      break;
    }
    if (state.startsWith('screen:')) {
      const title = state.slice(7);
      if (title === 'The window is too small') {
        sawTooSmall = true;
        check(resize, `${name}: window reported too small`);
        await page.setViewportSize(resize);
        await page.waitForFunction(() => document.querySelector('#screen h1')?.textContent !== 'The window is too small' ||
          document.getElementById('screen').hidden);
        continue;
      }
      if (title === 'Short break') sawBreak = true;
      await page.keyboard.press('Enter');
      await page.waitForFunction((t) => document.getElementById('screen').hidden ||
        document.querySelector('#screen h1')?.textContent !== t, title);
      continue;
    }
    const trial = await page.evaluate(() => document.body.dataset.trial);
    if (expectAfterReload) {
      check(trial === expectAfterReload, `${name}: after reload the page showed trial ${trial}, expected ${expectAfterReload}`);
      expectAfterReload = null;
    }
    if (reloadAfter && !reloaded && answers.size === reloadAfter) {
      reloaded = true;
      expectAfterReload = trial;
      await page.reload();
      lastTrial = '';
      continue;
    }
    await checkOneToOne(page, `${name} trial ${trial}`);
    const side = answers.size % 2 === 0 ? 'left' : 'right';
    // The page's trial reference carries the trial's row id (the export's trial_id) in its low 32 bits.
    answers.set(Number(trial) % 4294967296, side);
    await page.keyboard.press(side === 'left' ? 'ArrowLeft' : 'ArrowRight');
    lastTrial = trial;
  }
  check(/^[A-Z2-9]{8}$/.test(code), `${name}: completion code "${code}"`);
  check(answers.size === TRIALS, `${name}: answered ${answers.size} trials, expected ${TRIALS}`);
  check(sawBreak, `${name}: no break screen (break_every = 2)`);
  if (resize) check(sawTooSmall, `${name}: the too-small window was not refused`);
  if (reloadAfter) check(reloaded, `${name}: did not reload`);
  check(pageErrors.length === 0, `${name}: page errors: ${pageErrors.join('; ')}`);
  // The participant's token lives in the address's fragment, never in a URL sent to the server (nor a Referer).
  const url = new URL(page.url());
  const token = new URLSearchParams(url.hash.slice(1)).get('p');
  check(/^[0-9a-f]{32}$/.test(token || ''), `${name}: no token in the address's fragment (${page.url()})`);
  check(!url.search.includes(token), `${name}: the token is in the query: ${page.url()}`);
  check(!requested.some((u) => u.includes(token)), `${name}: the token appeared in a requested URL or Referer`);
  await context.close();
  return { token, answers, dpr };
}

let exitCode = 1;
try {
  const first = await runSession({ name: 'dpr1', dpr: 1, launch: { args: FLAGS, viewport: { width: 300, height: 200 } },
    resize: { width: 1000, height: 700 }, reloadAfter: 2 });
  const second = await runSession({ name: 'dpr2', dpr: 2,
    launch: { args: [...FLAGS, '--force-device-scale-factor=2', '--window-size=1000,700'], viewport: null } });

  // Stored rows: one per answered trial, with the side pressed, the viewport's devicePixelRatio and the browser.
  const exported = spawnSync(cli, ['study', 'export', database, '--format', 'json'], { encoding: 'utf8' });
  check(exported.status === 0, 'export failed: ' + exported.stderr);
  const rows = JSON.parse(exported.stdout).responses;
  check(rows.length === 2 * TRIALS, `stored ${rows.length} responses, expected ${2 * TRIALS}`);
  const sessions = [first, second];
  const observers = [...new Set(rows.map((r) => r.observer))];
  check(observers.length === 2, `observers ${observers}`);
  observers.forEach((observer, i) => {
    const mine = rows.filter((r) => r.observer === observer);
    const session = sessions[i];
    check(mine.length === TRIALS, `${observer}: ${mine.length} rows`);
    for (const r of mine) {
      const side = session.answers.get(r.trial_id);
      check(side !== undefined, `${observer}: stored trial ${r.trial_id} was not answered in the browser`);
      const leftChosen = (r.is_A_selected === 1) === (r.A_on_left === 1);
      check(leftChosen === (side === 'left'), `${observer}: trial ${r.trial_id} stored ${leftChosen ? 'left' : 'right'}, pressed ${side}`);
      check(r.device_pixel_ratio === session.dpr, `${observer}: stored devicePixelRatio ${r.device_pixel_ratio}, expected ${session.dpr}`);
      check(/Chrome/.test(r.user_agent), `${observer}: user agent "${r.user_agent}"`);
      check(r.response_ms > 0, `${observer}: response_ms ${r.response_ms}`);
    }
    check(mine.filter((r) => r.trial_kind === 'practice').length === 1, `${observer}: one practice row`);
    check(mine.filter((r) => r.trial_kind === 'catch').length === 1, `${observer}: one catch row`);
    check(mine.filter((r) => r.trial_kind === 'test').length === 3, `${observer}: three test rows`);
  });
  exitCode = failures === 0 ? 0 : 1;
} catch (e) {
  console.error(e);
} finally {
  server.kill('SIGTERM');
  // Chromium's helper processes may still be writing into a profile for a moment after context.close(): retry
  // (Node.js 18's rmSync does not by default), and never let the clean-up decide the test's result.
  try {
    fs.rmSync(work, { recursive: true, force: true, maxRetries: 10, retryDelay: 200 });
  } catch (e) {
    console.error(`warning: could not remove ${work}: ${e.message}`);
  }
}
console.log(exitCode === 0 ? `PASS: browser study session${active ? ' (active design)' : ''}` : `FAILED (${failures} checks)`);
process.exit(exitCode);
