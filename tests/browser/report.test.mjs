// Browser test of the study report: a tiny real study (stimulus set rendered with a reference, study created,
// served and answered by simulated observers through the HTTP API), `skinlab report` with its PDF, then the page
// in Debian's headless Chromium (playwright-core): every image loads, every table is filled, no NaN/inf/undefined
// is shown, every number of the findings links to an element of the page, and a full-page screenshot.
// Usage: node report.test.mjs /path/to/skinlab [SCREENSHOT.png]     Exit 0 pass, 1 fail, 77 skip.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { CHROMIUM, FLAGS, loadPlaywright, serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
const screenshotCopy = process.argv[3];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node report.test.mjs SKINLAB_CLI'); process.exit(1); }
const chromium = await loadPlaywright(here);
let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}
function run(args) {
  const started = Date.now();
  const result = spawnSync(cli, args, { encoding: 'utf8' });
  if (result.status !== 0) {
    console.error(`skinlab ${args.join(' ')} exited ${result.status}:\n${result.stdout}\n${result.stderr}`);
    process.exit(1);
  }
  console.log(`skinlab ${args[0]} ${args[1] || ''}: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  return result;
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-report-test-'));
process.on('exit', () => fs.rmSync(work, { recursive: true, force: true }));

// --- a small stimulus set of the built-in head with its object-space reference ---
fs.writeFileSync(path.join(work, 'spec.toml'), `
[set]
name = "report-test"
scene = "builtin:head"
seed = 1
[fixed]
render = { width = 200, height = 112, exposure_ev = 0.0 }
shadow = { resolution = 512 }
[[factor]]
name = "method"
levels = ["none", "gaussian-sum", "separable", "artistic"]
[[reference]]
method = "reference"
`);
run(['stimuli', 'build', path.join(work, 'spec.toml'), '-o', path.join(work, 'stimuli')]);
fs.writeFileSync(path.join(work, 'design.toml'),
  'title = "Report test"\nquestion = "Which face looks more like real skin?"\nseed = 5\n' +
  'conditions = ["none", "gaussian-sum", "separable", "artistic"]\nrepetitions = 2\n[practice]\ntrials = 1\n[catch]\nblank = 2\n');
const database = path.join(work, 'study.db');
run(['study', 'create', '--stimuli', path.join(work, 'stimuli'), '--design', path.join(work, 'design.toml'), '-o', database]);
fs.writeFileSync(path.join(work, 'truth.json'), JSON.stringify({ none: 0, 'gaussian-sum': 1.2, separable: 1.6, artistic: 0.6 }));

const { process: server, url } = await serve(cli, database);
try {
  run(['study', 'simulate', database, '--observer-count', '8', '--truth', path.join(work, 'truth.json'), '--seed', '3',
    '--random', '1', '--url', url]);
} finally {
  server.kill();
}

// --- the report, with its PDF ---
const reportDir = path.join(work, 'report');
const reported = run(['report', database, '-o', reportDir, '--bootstrap', '200']);
check(fs.existsSync(path.join(reportDir, 'index.html')), 'index.html written');
const pdf = path.join(reportDir, 'report.pdf');
check(fs.existsSync(pdf) && fs.readFileSync(pdf).subarray(0, 5).toString() === '%PDF-', 'report.pdf written and a PDF');
check(fs.statSync(pdf, { throwIfNoEntry: false })?.size > 20000, 'report.pdf has content');
for (const file of ['scale.json', 'agreement.json', 'agreement.csv', 'metrics/metrics.json'])
  check(fs.existsSync(path.join(reportDir, file)), file + ' written');
const agreement = JSON.parse(fs.readFileSync(path.join(reportDir, 'agreement.json'), 'utf8'));
check(agreement.agreement.some((row) => row.metric === 'image.flip_mean' && row.conditions === 4),
  'agreement.json has FLIP over the 4 conditions');
// Few conditions: Spearman's interval excludes 0 only where its exact p is below 0.05, and the settings say so.
check(agreement.agreement.every((row) => row.spearman_low === null || row.spearman_p === null ||
  row.spearman_p <= 0.05 || (row.spearman_low <= 0 && row.spearman_high >= 0)),
  'agreement.json: a Spearman interval excludes 0 only with exact p <= 0.05');
check(/exact interval/.test(agreement.settings.interval), 'agreement.json settings name the exact interval');
// The same agreement tables without a report, from the report's metrics folder.
run(['analyze', 'agreement', database, '--metrics', path.join(reportDir, 'metrics'), '-o', path.join(work, 'agreement'),
  '--bootstrap', '200']);
const standalone = JSON.parse(fs.readFileSync(path.join(work, 'agreement', 'agreement.json'), 'utf8'));
check(standalone.agreement.length === agreement.agreement.length, 'analyze agreement writes the same rows');
// Plain images on the command line: two stimulus PNGs (sRGB) get the image-wide scores; a bad --encoding is named.
const pngs = fs.readdirSync(path.join(reportDir, 'stimuli')).filter((f) => f.endsWith('.png')).sort();
run(['analyze', 'metrics', '--reference', path.join(reportDir, 'stimuli', pngs[0]), path.join(reportDir, 'stimuli', pngs[1]),
  '-o', path.join(work, 'plain'), '--ppd', '40']);
const plain = JSON.parse(fs.readFileSync(path.join(work, 'plain', 'metrics.json'), 'utf8'));
check(plain.comparisons[0].bands_measured === false && plain.comparisons[0].image.flip_mean > 0 &&
  plain.settings.flip.pixels_per_degree === 40, 'plain PNGs: image-wide scores, no bands, --ppd recorded');
const bad = spawnSync(cli, ['analyze', 'metrics', '--reference', path.join(reportDir, 'stimuli', pngs[0]),
  path.join(reportDir, 'stimuli', pngs[1]), '-o', path.join(work, 'bad'), '--encoding', 'gamma'], { encoding: 'utf8' });
check(bad.status === 2 && bad.stderr.includes('--encoding: "gamma" is not one of auto, srgb, linear'),
  'bad --encoding: exit 2 and a message naming it');
const html = fs.readFileSync(path.join(reportDir, 'index.html'), 'utf8');
check(!/(file:|\/tmp\/)/.test(html.replace(/<code>[^<]*<\/code>/g, '')), 'no absolute paths in links');

// --- the page in Chromium ---
const profile = fs.mkdtempSync(path.join(work, 'profile-'));
const context = await chromium.launchPersistentContext(profile, { executablePath: CHROMIUM, headless: true, args: FLAGS,
  viewport: { width: 1200, height: 900 } });
try {
  const page = context.pages()[0] || await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  const failedRequests = [];
  page.on('requestfailed', (r) => failedRequests.push(r.url()));
  await page.goto('file://' + path.join(reportDir, 'index.html'), { waitUntil: 'load' });
  const facts = await page.evaluate(() => {
    const images = Array.from(document.images).map((img) => ({ src: img.getAttribute('src'), ok: img.complete && img.naturalWidth > 0 }));
    const tables = Array.from(document.querySelectorAll('table')).map((t) => {
      const cells = Array.from(t.querySelectorAll('tbody td')).filter((td) => !td.classList.contains('diag'));
      return { id: t.id || t.previousElementSibling?.textContent?.slice(0, 40), rows: t.querySelectorAll('tbody tr').length,
        empty: cells.filter((td) => td.textContent.trim() === '').length };
    });
    const links = Array.from(document.querySelectorAll('ul.findings a.num')).map((a) => a.getAttribute('href'));
    const missing = links.filter((href) => !document.getElementById(href.slice(1)));
    const sections = ['findings', 'design', 'participants', 'stimuli', 'scale', 'metrics', 'agreement']
      .filter((id) => !document.getElementById(id));
    return { images, tables, links: links.length, missing, sections, text: document.body.innerText,
      svgs: document.querySelectorAll('svg.plot').length, scatters: document.querySelectorAll('svg.scatter').length,
      thumbnailLinks: Array.from(document.querySelectorAll('.thumbs a')).map((a) => a.getAttribute('href')) };
  });
  check(facts.images.length >= 4 + 4 + 8, `images: ${facts.images.length} (4 stimuli, 4 crops, 8 heat maps expected)`);
  for (const image of facts.images) check(image.ok, 'image loads: ' + image.src);
  check(failedRequests.length === 0, 'failed requests: ' + failedRequests.join(', '));
  check(facts.tables.length >= 6, `tables: ${facts.tables.length}`);
  for (const table of facts.tables) {
    check(table.rows > 0, `table ${table.id} has rows`);
    check(table.empty === 0, `table ${table.id}: ${table.empty} empty cells`);
  }
  check(!/\bNaN\b|\bnan\b|\binf\b|undefined|null/.test(facts.text), 'no NaN/inf/undefined/null shown');
  check(facts.links >= 6, `findings link their numbers (${facts.links} links)`);
  check(facts.missing.length === 0, 'findings links without target: ' + facts.missing.join(', '));
  check(facts.sections.length === 0, 'missing sections: ' + facts.sections.join(', '));
  check(facts.svgs >= 2 && facts.scatters >= 4, `plots: ${facts.svgs} (scatter ${facts.scatters})`);
  check(/metric that agrees best with the scale/.test(facts.text) && /after Holm's correction/.test(facts.text),
    'findings name the best metric, with its p corrected for the choice');
  check(/Predicted and measured/.test(facts.text) && /anchor/.test(facts.text),
    'the predicted-and-measured section (the set records ColorVideoVDP predictions)');
  check(/Slope [−\d.]+ \[[−\d.]+, [−\d.]+\], RMSE [\d.]+ JOD \[[\d.]+, [\d.]+\]/.test(facts.text),
    'slope and RMSE of predicted against measured, each with its interval');
  check(/exact p = [\d.]+, over 4 conditions/.test(facts.text), "Spearman's exact p over the block's 4 conditions");
  check(/the agreement below is circular/.test(facts.text), 'simulated observers: the circularity is stated');
  check(/Spearman's interval also spans its exact interval/.test(facts.text),
    "the agreement section says how Spearman's interval is made at few conditions");
  check(/scale 0–/.test(facts.text), 'heat maps print their colour scale');
  check(/Simulated observers\./.test(facts.text), 'the banner says the observers were simulated');
  check(/Which face looks more like real skin\?/.test(facts.text), 'the question is shown');
  check(facts.thumbnailLinks.every((href) => href && !href.startsWith('/') && fs.existsSync(path.join(reportDir, href))),
    'thumbnails link to files in the report folder');
  check(pageErrors.length === 0, 'page errors: ' + pageErrors.join('; '));
  const shot = path.join(work, 'report.png');
  await page.screenshot({ path: shot, fullPage: true });
  check(fs.statSync(shot).size > 50000, 'full-page screenshot has content');
  if (screenshotCopy) fs.copyFileSync(shot, screenshotCopy);
} finally {
  await context.close();
}
if (failures) { console.error(`${failures} check(s) failed`); process.exit(1); }
console.log('report test: all checks passed');
