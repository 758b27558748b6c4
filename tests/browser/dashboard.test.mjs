// The researcher dashboard in headless Chromium: /researcher#token=... (the token read from the fragment, never
// sent in a URL), the counts and the JOD scale rows appear, and update while answers are posted through the API;
// a wrong token shows the form. Saves a screenshot (argument 2, default: the temporary folder, removed).
// Usage: node dashboard.test.mjs /path/to/skinlab [SCREENSHOT.png]     Exit 0 pass, 1 fail, 77 skip.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { FLAGS, CHROMIUM, answerAll, createStudy, loadPlaywright, removeFolder, serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
const screenshot = process.argv[3];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node dashboard.test.mjs SKINLAB_CLI [SCREENSHOT]'); process.exit(1); }
const chromium = await loadPlaywright(here);

let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-dashboard-'));
const TOKEN = 'dashboard-researcher-token';
let server = null, browser = null, exitCode = 1;
try {
  const database = createStudy(cli, work, { title: 'Dashboard test', methods: ['a-method', 'b-method', 'c-method', 'd-method'] });
  const started = await serve(cli, database, ['--token', TOKEN]);
  server = started.process;
  const port = started.port;
  const base = `http://127.0.0.1:${port}/`;

  browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS });
  const context = await browser.newContext({ viewport: { width: 1100, height: 900 } });
  const requested = [];
  context.on('request', (r) => requested.push(r.url()));
  const page = await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));

  // A wrong token: the form, with a message.
  await page.goto(base + 'researcher#token=not-the-token');
  await page.waitForSelector('#login:not([hidden]) #login-error:not([hidden])', { timeout: 10000 });
  check(/Wrong researcher token/.test(await page.textContent('#login-error')), 'wrong token message');

  // The right token in the fragment: the dashboard; the fragment leaves the address bar.
  await page.goto('about:blank');
  await page.goto(base + 'researcher#token=' + TOKEN);
  await page.waitForFunction(() => Number(document.body.dataset.refreshes || 0) >= 1, null, { timeout: 10000 });
  check(!page.url().includes(TOKEN), 'the token stayed in the address: ' + page.url());
  check(await page.textContent('#participant-count') === '0', 'participants before anyone joined');
  check(await page.textContent('#viewing') === 'not recorded', 'viewing conditions placeholder');
  check(await page.textContent('#flagged') === 'not recorded', 'flagged trials placeholder');

  // Two participants answer everything: counts, progress and the scale appear at the next refresh.
  const first = await answerAll(port);
  const second = await answerAll(port);
  await page.waitForFunction(() => document.getElementById('participant-count').textContent === '2' &&
    document.querySelectorAll('#scale tr.scale-row').length === 4, null, { timeout: 20000, polling: 200 });
  const rows = await page.$$eval('#participants tbody tr', (trs) => trs.map((tr) => ({
    observer: tr.dataset.observer, answered: Number(tr.dataset.answered), total: Number(tr.dataset.total) })));
  check(rows.length === 2 && rows.every((r) => r.answered === r.total && r.total === first.answered),
    'participant rows: ' + JSON.stringify(rows));
  check(await page.textContent('#completed-count') === '2', 'completed count');
  check(await page.textContent('#response-count') === String(first.answered + second.answered), 'response count');
  check(/%/.test(await page.textContent('#catch-accuracy')), 'catch accuracy: ' + await page.textContent('#catch-accuracy'));
  const bars = await page.$$eval('#rt-histogram rect.bar', (rects) => rects.map((r) => Number(r.dataset.count)));
  check(bars.reduce((a, b) => a + b, 0) === first.answered + second.answered - 2, 'histogram counts ' + bars.join(','));
  const scaleBefore = await page.evaluate(() => document.body.dataset.scaleComputedAt);
  const jodBefore = await page.$$eval('#scale tr.scale-row', (trs) => trs.map((tr) => tr.dataset.jod).join(','));
  check(await page.$$eval('#scale svg circle.point', (c) => c.length) === 4, 'scale plot points');

  // A third participant: the dashboard follows without a reload (the scale is recomputed, at most every 5 s).
  // It reports its viewing conditions and one trial shown while the page was hidden.
  const third = await answerAll(port, { hiddenAt: 1, viewing: { screen_width: 1920, screen_height: 1080,
    colour_depth: 24, fullscreen: true, pointer_fine: true, touch_points: 0 } });
  await page.waitForFunction((before) => document.getElementById('participant-count').textContent === '3' &&
    document.body.dataset.scaleComputedAt !== before, scaleBefore, { timeout: 30000, polling: 250 });
  check(await page.textContent('#response-count') === String(first.answered + second.answered + third.answered),
    'response count after the third participant');
  await page.waitForSelector('#viewing-table tr[data-observer="' + third.observer + '"]', { timeout: 10000 });
  check(/1920 × 1080/.test(await page.textContent('#viewing-table tr[data-observer="' + third.observer + '"]')),
    'viewing conditions row: ' + await page.textContent('#viewing'));
  check(await page.getAttribute('#flagged', 'data-count') === '1', 'flagged count: ' + await page.textContent('#flagged'));
  check(/hidden, focus lost/.test(await page.textContent('#flagged-list')), 'flagged trial: ' + await page.textContent('#flagged'));
  const jodAfter = await page.$$eval('#scale tr.scale-row', (trs) => trs.map((tr) => tr.dataset.jod).join(','));
  check(jodAfter !== jodBefore, 'the scale did not change with more answers: ' + jodAfter);
  const shot = screenshot || path.join(work, 'dashboard.png');
  fs.mkdirSync(path.dirname(shot), { recursive: true });
  await page.screenshot({ path: shot, fullPage: true });
  check(fs.statSync(shot).size > 20000, 'screenshot has content');
  if (screenshot) console.log('screenshot: ' + screenshot);

  check(!requested.some((u) => u.includes(TOKEN)), 'the token appeared in a requested URL');
  check(pageErrors.length === 0, 'page errors: ' + pageErrors.join('; '));
  exitCode = failures === 0 ? 0 : 1;
} catch (e) {
  console.error(e);
} finally {
  if (browser) await browser.close().catch(() => {});
  if (server) server.kill('SIGTERM');
  removeFolder(work);
}
console.log(exitCode === 0 ? 'PASS: researcher dashboard' : `FAILED (${failures} checks)`);
process.exit(exitCode);
