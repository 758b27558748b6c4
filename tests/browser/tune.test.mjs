// Browser test of `skinlab tune` in Debian's headless Chromium (playwright-core): the page builds its controls from
// the server's declarations, moving a slider with the keyboard changes the image and the reported parameters, a
// typed bad value shows the same one line as `skinlab render` prints, and two tabs tune at once, each getting its
// own image. Real server, real EGL rendering (llvmpipe).
// Usage: node tune.test.mjs /path/to/skinlab [SCREENSHOT.png]     Exit 0 pass, 1 fail, 77 skip.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { CHROMIUM, FLAGS, loadPlaywright, serveTune } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
const screenshot = process.argv[3];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node tune.test.mjs SKINLAB_CLI [SCREENSHOT]'); process.exit(1); }
const chromium = await loadPlaywright(here);
let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-tune-browser-'));
let server = null;
let browser = null;
let exitCode = 1;
try {
  const started = await serveTune(cli, ['--width', '320', '--height', '180', '--export-dir', work]);
  server = started.process;
  const { url } = started;
  browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS });
  const context = await browser.newContext({ viewport: { width: 1400, height: 1000 } });
  const page = await context.newPage();
  page.on('pageerror', (e) => check(false, 'page error: ' + e.message));
  await page.goto(url);
  const params = async (p) => JSON.parse(await p.textContent('#params'));
  const imageSrc = (p) => p.getAttribute('#image', 'src');
  await page.waitForFunction(() => (document.getElementById('image').src || '').startsWith('data:image/png'), null,
    { timeout: 60000 });

  // The method selector offers every method of the table; choosing one shows its keys.
  const methods = JSON.parse(spawnSync(cli, ['methods', '--json'], { encoding: 'utf8' }).stdout);
  const offered = await page.$$eval('#method option', (o) => o.map((x) => x.value));
  check(JSON.stringify(offered) === JSON.stringify(methods.map((m) => m.name)), `methods offered: ${offered}`);
  await page.selectOption('#method', 'separable');
  await page.waitForFunction(() => document.getElementById('params').textContent.includes('"method": "separable"'),
    null, { timeout: 60000 });
  await page.waitForSelector('input[data-key="sss.width_mm"]');
  const separable = methods.find((m) => m.name === 'separable');
  for (const p of separable.parameters) {
    const key = p.type === 'vec3' ? `sss.${p.name}[0]` : `sss.${p.name}`;
    check(await page.$(`[data-key="${key}"]`) !== null, `no control for ${key}`);
  }
  const width = separable.parameters.find((p) => p.name === 'width_mm');
  const slider = page.locator('input[data-key="sss.width_mm"]');
  check(await slider.getAttribute('type') === 'range', 'width_mm is not a slider');
  check(Number(await page.inputValue('input[data-key-number="sss.width_mm"]')) === width.default,
    'the width box does not show the declared default');

  // Moving the slider (keyboard, as a user) changes the image and the reported width.
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('#'));
  const before = await imageSrc(page);
  const widthBefore = (await params(page)).resolved.sss.width_mm;
  await slider.focus();
  await page.keyboard.press('PageUp');
  await page.waitForFunction((w) => {
    const p = JSON.parse(document.getElementById('params').textContent);
    return p.resolved.sss.width_mm !== w;
  }, widthBefore, { timeout: 60000 });
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('re-ran sss'), null,
    { timeout: 60000 });
  const after = await imageSrc(page);
  const widthAfter = (await params(page)).resolved.sss.width_mm;
  check(widthAfter > widthBefore, `width did not grow: ${widthBefore} → ${widthAfter}`);
  check(after !== before, 'the image did not change with the slider');
  check(/re-ran sss\)/.test(await page.textContent('#status')), 'an [sss] change re-ran more than the SSS stage');
  // The kernel plot is drawn.
  await page.waitForFunction(() => document.querySelectorAll('#kernel polyline').length >= 6, null, { timeout: 30000 });

  // A typed bad value: the CLI's one line, the last image kept.
  const box = page.locator('input[data-key-number="sss.width_mm"]');
  await box.fill('500');
  await box.press('Enter');
  await page.waitForSelector('#error:not([hidden])', { timeout: 30000 });
  const shown = (await page.textContent('#error')).trim();
  const cliRun = spawnSync(cli, ['render', '--scene', 'builtin:head', '--set', 'sss.method="separable"', '--set',
    'sss.width_mm=500', '-o', path.join(work, 'x.exr')], { encoding: 'utf8' });
  check(cliRun.status === 2, 'the CLI did not refuse width 500');
  check(shown === cliRun.stderr.trim(), `page shows "${shown}", the CLI "${cliRun.stderr.trim()}"`);
  check(await imageSrc(page) === after, 'the image changed on a bad value');
  // A good value clears the error.
  await box.fill('1.5');
  await box.press('Enter');
  await page.waitForSelector('#error[hidden]', { state: 'attached', timeout: 60000 });
  await page.waitForFunction(() => JSON.parse(document.getElementById('params').textContent).resolved.sss.width_mm === 1.5,
    null, { timeout: 60000 });
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true });

  // Two tabs at once: each moves its own slider and gets its own parameters and image.
  const second = await context.newPage();
  await second.goto(url);
  await second.waitForFunction(() => (document.getElementById('image').src || '').startsWith('data:image/png'), null,
    { timeout: 60000 });
  await second.selectOption('#method', 'artistic');
  await second.waitForFunction(() => document.getElementById('params').textContent.includes('"method": "artistic"'),
    null, { timeout: 60000 });
  const strength = second.locator('input[data-key="sss.artistic_strength[0]"]');
  const firstBox = page.locator('input[data-key-number="sss.width_mm"]');
  await Promise.all([
    (async () => { await strength.focus(); for (let i = 0; i < 3; i++) await second.keyboard.press('PageUp'); })(),
    (async () => { await firstBox.fill('4.25'); await firstBox.press('Enter'); })(),
  ]);
  await page.waitForFunction(() => JSON.parse(document.getElementById('params').textContent).resolved.sss.width_mm === 4.25,
    null, { timeout: 60000 });
  await second.waitForFunction(() => {
    const p = JSON.parse(document.getElementById('params').textContent);
    return p.resolved.sss.method === 'artistic' && p.resolved.sss.artistic_strength[0] > 0.48;
  }, null, { timeout: 60000 });
  check((await params(page)).resolved.sss.method === 'separable', 'the first tab lost its method');
  check(await page.isHidden('#error'), 'the first tab shows an error');
  check(await second.isHidden('#error'), 'the second tab shows an error');
  check(await imageSrc(page) !== await imageSrc(second), 'both tabs show the same image');
  exitCode = failures ? 1 : 0;
} catch (e) {
  console.error('FAIL: ' + (e.stack || e));
  exitCode = 1;
} finally {
  if (browser) await browser.close();
  if (server) server.kill('SIGTERM');
  fs.rmSync(work, { recursive: true, force: true });
}
console.log(exitCode === 0 ? 'PASS' : `${failures} failure(s)`);
process.exit(exitCode);
