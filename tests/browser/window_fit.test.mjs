// Browser test of the window-size check: a study of 896×504 stimuli fits a 1920×1080 display at
// one image pixel per device pixel, so Chromium at 1920×1080 goes straight to consent and shows trials 1:1; in a
// 1366×768 window the page says the window is too small, with the size needed, before consent: nobody joins and
// nothing is stored until the window is large enough. And `study create` refuses a design whose stimuli cannot fit
// its declared viewport (1280×720 stimuli side by side on a 1920×1080 display).
// Usage: node window_fit.test.mjs /path/to/skinlab     Exit 0 pass, 1 fail, 77 skip.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { CHROMIUM, FLAGS, createStudy, loadPlaywright, serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node window_fit.test.mjs SKINLAB_CLI'); process.exit(1); }
const chromium = await loadPlaywright(here);
let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}
const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-window-fit-'));
const participants = (database) => {
  const status = spawnSync(cli, ['study', 'status', database], { encoding: 'utf8' });
  const m = /(\d+) participants/.exec(status.stdout);
  return m ? Number(m[1]) : -1;
};
const heading = (page) => page.evaluate(() => document.getElementById('screen').hidden ? '' :
  document.querySelector('#screen h1')?.textContent || '');

let server = null, exitCode = 1;
try {
  // 1280×720 stimuli side by side need 2608 × 820 CSS pixels: refused at `study create`, with the size.
  const tooLarge = path.join(work, 'large');
  fs.mkdirSync(tooLarge);
  let refused = '';
  try { createStudy(cli, tooLarge, { width: 1280, height: 720 }); } catch (e) { refused = e.message; }
  check(/display\.viewport_width: the trials need 2608 × 820 CSS pixels/.test(refused) &&
    /1920 × 1080 viewport/.test(refused), `study create did not refuse 1280×720 stimuli: "${refused}"`);
  check(!fs.existsSync(path.join(tooLarge, 'study.db')), 'a refused study left a file');

  const database = createStudy(cli, work, { width: 896, height: 504, title: 'Window test' });
  server = await serve(cli, database);
  const base = `http://127.0.0.1:${server.port}/`;

  // 1366×768: too small, said before consent; nobody has joined.
  const small = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS });
  const smallPage = await small.newPage({ viewport: { width: 1366, height: 768 } });
  await smallPage.goto(base);
  await smallPage.waitForFunction(() => document.body.dataset.tooSmall !== undefined, null, { timeout: 20000 });
  check(await heading(smallPage) === 'The window is too small', 'too-small screen not shown at 1366×768');
  const message = await smallPage.textContent('#screen');
  check(message.includes('1840 × 604'), `the needed size is not named: "${message}"`);
  check(await smallPage.$('#agree') === null, 'consent offered in a too-small window');
  check(participants(database) === 0, 'a participant joined from a too-small window');
  // Enlarged, the page goes on by itself to consent.
  await smallPage.setViewportSize({ width: 1920, height: 1080 });
  await smallPage.waitForFunction(() => document.getElementById('agree') !== null, null, { timeout: 20000 });
  check(participants(database) === 0, 'joined before agreeing');
  await small.close();

  // 1920×1080: consent at once, then trials shown at one image pixel per device pixel.
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS });
  const page = await browser.newPage({ viewport: { width: 1920, height: 1080 } });
  await page.goto(base);
  await page.waitForFunction(() => document.getElementById('agree') !== null, null, { timeout: 20000 });
  check(await heading(page) === 'Window test', `1920×1080: first screen "${await heading(page)}", expected consent`);
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelector('#screen h1')?.textContent === 'Instructions', null,
    { timeout: 20000 });
  await page.keyboard.press(' ');
  await page.waitForFunction(() => {
    const stage = document.getElementById('stage');
    return !stage.hidden && stage.style.visibility === 'visible';
  }, null, { timeout: 20000 });
  const sizes = await page.evaluate(() => ['left', 'right'].map((id) => {
    const r = document.getElementById(id).getBoundingClientRect();
    return [r.width, r.height, r.right <= window.innerWidth && r.bottom <= window.innerHeight];
  }));
  for (const [w, h, inside] of sizes) check(w === 896 && h === 504 && inside, `1920×1080: image shown ${w}×${h}, inside ${inside}`);
  check(participants(database) === 1, 'the 1920×1080 participant did not join');
  await browser.close();
  exitCode = failures === 0 ? 0 : 1;
} catch (e) {
  console.error(e);
} finally {
  if (server) server.process.kill('SIGTERM');
  try { fs.rmSync(work, { recursive: true, force: true, maxRetries: 10, retryDelay: 200 }); } catch (e) { /* kept */ }
}
console.log(exitCode === 0 ? 'PASS: window fit' : `FAILED (${failures} checks)`);
process.exit(exitCode);
