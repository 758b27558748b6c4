// Browser test of `skinlab tune` against another site's page, in Debian's headless Chromium (playwright-core): a page
// served from another origin on loopback (another port of 127.0.0.1, and localhost) sends the requests any web page
// can send without reading the answer — fetch(..., {mode: 'no-cors'}) with a text/plain body, and a form posted as
// text/plain — to /api/export, /api/reference and /api/job/cancel. Nothing may be written to the export folder, no
// render may start. Then the tuning page itself exports (its token and JSON accepted), is asked before it replaces
// a file, and keeps the file when the user says no. Real server, real EGL rendering (llvmpipe).
// Usage: node tune_cross_site.test.mjs /path/to/skinlab     Exit 0 pass, 1 fail, 77 skip.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { CHROMIUM, FLAGS, loadPlaywright, serveTune } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node tune_cross_site.test.mjs SKINLAB_CLI'); process.exit(1); }
const chromium = await loadPlaywright(here);
let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

// The processes whose parent is `pid` (from /proc).
function childrenOf(pid) {
  const out = [];
  for (const entry of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(entry)) continue;
    try {
      const stat = fs.readFileSync(`/proc/${entry}/stat`, 'utf8');
      const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
      if (Number(fields[1]) === pid) out.push(Number(entry));
    } catch (e) { /* ended meanwhile */ }
  }
  return out;
}

// A GET from node (no Origin, no Sec-Fetch-Site): status and body.
function get(url) {
  return new Promise((resolve, reject) => {
    http.get(url, (res) => {
      let body = '';
      res.on('data', (d) => { body += d; });
      res.on('end', () => resolve({ status: res.statusCode, body }));
    }).on('error', reject);
  });
}

// The other site's page: on load it sends the attacks to the tuning server at `target` and then says "sent".
function attackerPage(target) {
  const small = ['render.width=64', 'render.height=64', 'shadow.resolution=256'];
  const exportBody = JSON.stringify({ scene: 'builtin:head', name: 'tuned', overwrite: true, overrides: small });
  const pwnedBody = JSON.stringify({ scene: 'builtin:head', name: 'pwned', overrides: small });
  const referenceBody = JSON.stringify({ scene: 'builtin:head', overrides: small });
  return `<!doctype html><meta charset="utf-8"><title>another site</title>
<form id="form" method="POST" action="${target}api/export" enctype="text/plain" target="sink">
<input name='${pwnedBody.slice(0, -1)}, "x": "' value='"}'></form><iframe name="sink"></iframe>
<script>
(async () => {
  const send = (path, body) => fetch(${JSON.stringify(target)} + path,
    { method: 'POST', mode: 'no-cors', headers: { 'Content-Type': 'text/plain' }, body }).catch(() => null);
  await send('api/export', ${JSON.stringify(exportBody)});
  await send('api/export', ${JSON.stringify(pwnedBody)});
  await send('api/reference', ${JSON.stringify(referenceBody)});
  await send('api/job/cancel', '{"id": "job1"}');
  // A simple request with a JSON body but no JSON content type, and a same-looking JSON one (preflighted: refused
  // by the browser itself since the server answers no CORS).
  await fetch(${JSON.stringify(target)} + 'api/export', { method: 'POST', mode: 'cors',
    headers: { 'Content-Type': 'application/json' }, body: ${JSON.stringify(pwnedBody)} }).catch(() => null);
  document.getElementById('form').submit();
  setTimeout(() => { document.title = 'sent'; }, 1500);
})();
</script>`;
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-tune-cross-site-'));
const exportDir = path.join(work, 'exports');
fs.mkdirSync(exportDir);
const original = '# the researcher\'s own tuned scene\n[sss]\nmethod = "separable"\n';
fs.writeFileSync(path.join(exportDir, 'tuned.toml'), original);
let server = null;
let browser = null;
let other = null;
let exitCode = 1;
try {
  const started = await serveTune(cli, ['--width', '160', '--height', '90', '--export-dir', exportDir]);
  server = started.process;
  const { url, port } = started;
  // The other site: its own port on loopback.
  other = http.createServer((req, res) => {
    const target = req.url.startsWith('/localhost') ? `http://localhost:${port}/` : url;
    res.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8' });
    res.end(attackerPage(target));
  });
  await new Promise((resolve) => other.listen(0, '127.0.0.1', resolve));
  const otherPort = other.address().port;

  browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: FLAGS });
  const context = await browser.newContext();
  const evil = await context.newPage();
  for (const page of [`http://127.0.0.1:${otherPort}/`, `http://localhost:${otherPort}/`,
    `http://localhost:${otherPort}/localhost`]) {
    await evil.goto(page);
    await evil.waitForFunction(() => document.title === 'sent', null, { timeout: 30000 });
  }
  await new Promise((r) => setTimeout(r, 500));
  check(fs.readFileSync(path.join(exportDir, 'tuned.toml'), 'utf8') === original,
    'another site overwrote tuned.toml');
  const written = fs.readdirSync(exportDir).sort();
  check(JSON.stringify(written) === JSON.stringify(['tuned.toml']), `another site wrote files: ${written}`);
  check(childrenOf(server.pid).length === 0, `another site started renders: ${childrenOf(server.pid)}`);
  check((await get(url + 'api/job?id=job1')).status === 404, 'another site created a job');

  // The tuning page itself: its requests carry the token and JSON, so export works; replacing asks first.
  const page = await context.newPage();
  page.on('pageerror', (e) => check(false, 'page error: ' + e.message));
  await page.goto(url);
  await page.waitForFunction(() => (document.getElementById('image').src || '').startsWith('data:image/png'), null,
    { timeout: 60000 });
  await page.fill('#export-name', 'fresh');
  await page.click('#export');
  await page.waitForSelector('#export-result:not([hidden])', { timeout: 60000 });
  check(fs.existsSync(path.join(exportDir, 'fresh.toml')), 'the page could not export');
  check(fs.existsSync(path.join(exportDir, 'fresh.include.toml')), 'the page wrote no include file');

  const dialogs = [];
  let accept = false;
  page.on('dialog', async (dialog) => { dialogs.push(dialog.message()); if (accept) await dialog.accept(); else await dialog.dismiss(); });
  await page.fill('#export-name', 'tuned');
  await page.click('#export');
  await page.waitForSelector('#error:not([hidden])', { timeout: 60000 });
  check(dialogs.length === 1 && dialogs[0].includes('tuned.toml'), `no question before replacing: ${dialogs}`);
  check((await page.textContent('#error')).includes('already in the export folder'),
    `refusal not shown: ${await page.textContent('#error')}`);
  check(fs.readFileSync(path.join(exportDir, 'tuned.toml'), 'utf8') === original, 'replaced although the user said no');
  accept = true;
  await page.evaluate(() => { document.getElementById('export-result').hidden = true; });
  await page.click('#export');
  await page.waitForSelector('#export-result:not([hidden])', { timeout: 60000 });
  check(dialogs.length === 2, `asked ${dialogs.length} times`);
  check(fs.readFileSync(path.join(exportDir, 'tuned.toml'), 'utf8').startsWith('# Exported by `skinlab tune`'),
    'not replaced although the user said yes');
  exitCode = failures ? 1 : 0;
} catch (e) {
  console.error('FAIL: ' + (e.stack || e));
  exitCode = 1;
} finally {
  if (browser) await browser.close();
  if (other) other.close();
  if (server) server.kill('SIGTERM');
  fs.rmSync(work, { recursive: true, force: true });
}
console.log(exitCode === 0 ? 'PASS' : `${failures} failure(s)`);
process.exit(exitCode);
