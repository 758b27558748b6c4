// Shared by the browser tests: a tiny stimulus set and study, `skinlab study serve` and `skinlab tune` started on an
// ephemeral port, a participant session driven with the keyboard, and HTTP(S) requests from a chosen local address.
import { spawn, spawnSync } from 'node:child_process';
import { createHash } from 'node:crypto';
import fs from 'node:fs';
import http from 'node:http';
import https from 'node:https';
import net from 'node:net';
import path from 'node:path';
import readline from 'node:readline';
import zlib from 'node:zlib';

export const SKIP = 77;
export const CHROMIUM = '/usr/bin/chromium';
export const FLAGS = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync'];

export async function loadPlaywright(here) {
  if (!fs.existsSync(CHROMIUM)) { console.log('SKIP: /usr/bin/chromium not installed'); process.exit(SKIP); }
  try {
    return (await import(path.join(here, 'node_modules/playwright-core/index.mjs'))).chromium;
  } catch (e) {
    console.log('SKIP: playwright-core not installed (run npm install in tests/browser)');
    process.exit(SKIP);
  }
}

const crcTable = Array.from({ length: 256 }, (_, n) => {
  let c = n;
  for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
function crc32(buffer) {
  let c = 0xffffffff;
  for (const b of buffer) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}
function chunk(type, data) {
  const length = Buffer.alloc(4); length.writeUInt32BE(data.length);
  const body = Buffer.concat([Buffer.from(type, 'ascii'), data]);
  const crc = Buffer.alloc(4); crc.writeUInt32BE(crc32(body));
  return Buffer.concat([length, body, crc]);
}
// 8-bit RGB PNG of `rgb` (width × height × 3 bytes, rows top first).
export function encodePng(width, height, rgb) {
  const header = Buffer.alloc(13);
  header.writeUInt32BE(width, 0); header.writeUInt32BE(height, 4);
  header[8] = 8; header[9] = 2;
  const raw = Buffer.alloc((width * 3 + 1) * height);
  for (let y = 0; y < height; y++) rgb.copy(raw, y * (width * 3 + 1) + 1, y * width * 3, (y + 1) * width * 3);
  return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', header),
    chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
}

// One block, `methods` conditions of W × H pixels; design with one practice and one blank catch trial (and
// `designExtra`, TOML tables appended). Returns the study path.
export function createStudy(cli, work, { methods = ['reference-like', 'separable', 'artistic'], title = 'Online test',
  width: W = 96, height: H = 64, designExtra = '' } = {}) {
  fs.mkdirSync(path.join(work, 'stimuli/png'), { recursive: true });
  const manifest = { format: 'skinlab-stimuli', version: 1, set: 'online-test', spec_sha256: '0'.repeat(64),
    renderer: { gl_renderer: 'none', gl_version: '', skinlab_version: '' }, stimuli: [] };
  methods.forEach((method, m) => {
    const rgb = Buffer.alloc(W * H * 3);
    for (let i = 0; i < W * H; i++) for (let k = 0; k < 3; k++) rgb[i * 3 + k] = (40 + 70 * m + 50 * k + (i % 2) * 30) % 256;
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
    `title = "${title}"\nquestion = "Which looks more like real skin?"\nseed = 5\nbreak_every = 0\nrepetitions = 1\n` +
    '[practice]\ntrials = 1\n[catch]\nblank = 1\n' + designExtra);
  const database = path.join(work, 'study.db');
  const created = spawnSync(cli, ['study', 'create', '--stimuli', path.join(work, 'stimuli'), '--design',
    path.join(work, 'design.toml'), '-o', database], { encoding: 'utf8' });
  if (created.status !== 0) throw new Error('study create failed: ' + created.stderr);
  return database;
}

// Starts `cli ARGS...` and resolves { process, port, url } once a line of its output matches `address` (its first
// group: the server's http://127.0.0.1:PORT/ address); rejects if it cannot start, exits first or prints no address
// within `timeoutMs` (then it is stopped).
function startServer(cli, args, address, timeoutMs, name) {
  const server = spawn(cli, args, { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => { server.kill('SIGTERM'); reject(new Error(name + ' did not start')); }, timeoutMs);
    server.on('exit', (code) => { clearTimeout(timer); reject(new Error(name + ' exited with ' + code)); });
    server.on('error', (e) => { clearTimeout(timer); reject(new Error(name + ' did not start: ' + e.message)); });
    readline.createInterface({ input: server.stdout }).on('line', (line) => {
      const m = address.exec(line);
      if (m) { clearTimeout(timer); resolve({ process: server, port: Number(new URL(m[1]).port), url: m[1] }); }
    });
  });
}

// `skinlab study serve DB --port 0 ARGS...`; resolves { process, port, url } once it prints its address.
export function serve(cli, database, args = []) {
  return startServer(cli, ['study', 'serve', database, '--port', '0', ...args],
    /serving .* on (http:\/\/127\.0\.0\.1:\d+\/)/, 20000, 'server');
}

// `skinlab tune --port 0 ARGS...`; resolves { process, port, url } once it prints its address.
export function serveTune(cli, args = []) {
  return startServer(cli, ['tune', '--port', '0', ...args], /tuning on (http:\/\/127\.0\.0\.1:\d+\/)/, 30000,
    'skinlab tune');
}

export function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.on('error', reject);
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

// One request; `options`: { method, headers, body, localAddress, tls (https, any certificate), host, servername }.
export function request(port, target, options = {}) {
  const { method = 'GET', headers = {}, body, localAddress, tls = false, host = '127.0.0.1' } = options;
  return new Promise((resolve, reject) => {
    const req = (tls ? https : http).request({ host, port, path: target, method, headers, localAddress,
      rejectUnauthorized: false, servername: options.servername, agent: false }, (res) => {
      const parts = [];
      res.on('data', (d) => parts.push(d));
      res.on('end', () => {
        const text = Buffer.concat(parts).toString('utf8');
        let json = null;
        try { json = JSON.parse(text); } catch (e) { /* not JSON */ }
        resolve({ status: res.statusCode, headers: res.headers, text, json });
      });
    });
    req.on('error', reject);
    req.setTimeout(20000, () => req.destroy(new Error('request timed out')));
    if (body !== undefined) req.write(body);
    req.end();
  });
}

// Joins and answers every trial through the API ("left" each time); returns the number answered.
// `viewing`: extra /api/session fields (the page's viewing conditions); `hiddenAt`: answer number (from 0) sent as
// shown while the page was hidden.
export async function answerAll(port, { tls = false, headers = {}, localAddress, limit = Infinity, viewing = {},
  hiddenAt = -1 } = {}) {
  const json = { 'Content-Type': 'application/json', ...headers };
  const post = (target, body) => request(port, target, { method: 'POST', headers: json, body: JSON.stringify(body), localAddress, tls });
  const joined = await post('/api/join', {});
  if (joined.status !== 201) throw new Error('join: ' + joined.status + ' ' + joined.text);
  const token = joined.json.token;
  const screenSize = { viewport_width: 1280, viewport_height: 800, device_pixel_ratio: 1 };
  const session = await post('/api/session', { token, ...screenSize, ...viewing });
  let state = session.json, answered = 0;
  while (state.trial && answered < limit) {
    const r = await post('/api/response', { token, trial: state.trial.id, side: answered % 3 === 0 ? 'right' : 'left',
      session: session.json.session, response_ms: 500 + 137 * answered, client_time: new Date().toISOString(), ...screenSize,
      ...(hiddenAt === answered ? { page_hidden: true, focus_lost: true, fullscreen: false } : {}) });
    if (r.status !== 200) throw new Error('response: ' + r.status + ' ' + r.text);
    state = r.json;
    answered++;
  }
  return { token, observer: joined.json.observer, answered };
}

// Completes a participant session in the page with the keyboard; returns { answers: Map(trial row id → side), code }.
export async function runSession(page, url, check, name) {
  await page.goto(url);
  const answers = new Map();
  let lastTrial = '', code = '';
  for (let step = 0; step < 40; step++) {
    const state = await (await page.waitForFunction((last) => {
      if (document.body.dataset.completed === 'true') return 'done';
      const stage = document.getElementById('stage');
      const screen = document.getElementById('screen');
      if (!stage.hidden && stage.style.visibility === 'visible' && document.body.dataset.trial !== last &&
          !document.body.classList.contains('busy')) return 'trial';
      if (!screen.hidden && screen.querySelector('h1')) return 'screen:' + screen.querySelector('h1').textContent;
      return false;
    }, lastTrial, { timeout: 20000, polling: 50 })).jsonValue();
    if (state === 'done') { code = await page.textContent('#completion-code'); break; }
    if (state.startsWith('screen:')) {
      const title = state.slice(7);
      check(title !== 'The window is too small', `${name}: window reported too small`);
      await page.keyboard.press('Enter');
      await page.waitForFunction((t) => document.getElementById('screen').hidden ||
        document.querySelector('#screen h1')?.textContent !== t, title);
      continue;
    }
    const trial = await page.evaluate(() => document.body.dataset.trial);
    const side = answers.size % 2 === 0 ? 'left' : 'right';
    answers.set(Number(trial) % 4294967296, side);
    await page.keyboard.press(side === 'left' ? 'ArrowLeft' : 'ArrowRight');
    lastTrial = trial;
  }
  check(/^[A-Z2-9]{8}$/.test(code), `${name}: completion code "${code}"`);
  // The participant's token: in the address's fragment (never sent to a server).
  const token = new URLSearchParams(new URL(page.url()).hash.slice(1)).get('p') || '';
  check(/^[0-9a-f]{32}$/.test(token), `${name}: no token in the address's fragment: ${page.url()}`);
  return { answers, code, token };
}

export function removeFolder(work) {
  try {
    fs.rmSync(work, { recursive: true, force: true, maxRetries: 10, retryDelay: 200 });
  } catch (e) {
    console.error(`warning: could not remove ${work}: ${e.message}`);
  }
}
