// The deployment of experiments/deploy/: nginx (Debian's, as a non-root process, everything in a temporary folder)
// terminates TLS with a self-signed certificate on an ephemeral loopback port and forwards to `skinlab study serve
// --public-host localhost` on another; headless Chromium completes one participant session through https://.
// Checks: every answer stored as pressed, the client address forwarded by nginx stored with the participant (and
// one spoofed by the client replaced by nginx), a spoofed X-Forwarded-For from a peer that is not the proxy not
// believed, the stimulus caching headers through the proxy, HSTS, nginx's body limit.
// Usage: node deploy_https.test.mjs /path/to/skinlab     Exit 0 pass, 1 fail, 77 skip (no nginx, openssl, chromium).
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { FLAGS, CHROMIUM, SKIP, answerAll, createStudy, freePort, loadPlaywright, removeFolder, request, runSession,
  serve } from './study_fixture.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cli = process.argv[2];
if (!cli || !fs.existsSync(cli)) { console.error('usage: node deploy_https.test.mjs SKINLAB_CLI'); process.exit(1); }
const nginxBinary = ['/usr/sbin/nginx', '/usr/bin/nginx'].find((p) => fs.existsSync(p));
if (!nginxBinary) { console.log('SKIP: nginx not installed (apt-get install nginx)'); process.exit(SKIP); }
if (spawnSync('openssl', ['version']).status !== 0) { console.log('SKIP: openssl not installed'); process.exit(SKIP); }
const chromium = await loadPlaywright(here);

let failures = 0;
function check(condition, message) {
  if (!condition) { failures++; console.error('FAIL: ' + message); }
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'skinlab-deploy-'));
const TOKEN = 'deploy-researcher-token';
let server = null, nginx = null, exitCode = 1;
try {
  const database = createStudy(cli, work, { title: 'Deployment test' });
  const TRIALS = 5; // 1 practice + 3 pairs + 1 catch

  // nginx's folder: configuration, certificate, pid, logs, temporary files. nginx runs as a non-root user: when
  // the test runs as root, as nobody (the folder is given to that user).
  const prefix = path.join(work, 'nginx');
  fs.mkdirSync(prefix);
  const cert = path.join(prefix, 'cert.pem'), key = path.join(prefix, 'key.pem');
  const made = spawnSync('openssl', ['req', '-x509', '-newkey', 'ec', '-pkeyopt', 'ec_paramgen_curve:prime256v1', '-nodes',
    '-keyout', key, '-out', cert, '-days', '2', '-subj', '/CN=localhost', '-addext', 'subjectAltName=DNS:localhost'],
  { encoding: 'utf8' });
  if (made.status !== 0) throw new Error('openssl: ' + made.stderr);

  const started = await serve(cli, database, ['--public-host', 'localhost', '--token', TOKEN]);
  server = started.process;
  const serverPort = started.port;
  const httpsPort = await freePort();
  const site = path.join(prefix, 'skinlab-site.conf');
  const generated = spawnSync(cli, ['study', 'deploy-config', '--server-name', 'localhost', '--upstream',
    `127.0.0.1:${serverPort}`, '--cert', cert, '--key', key, '--listen', `127.0.0.1:${httpsPort}`,
    '--access-log', `${prefix}/site-access.log`, '-o', site], { encoding: 'utf8' });
  check(generated.status === 0, 'deploy-config failed: ' + generated.stderr);
  check((fs.statSync(site).mode & 0o777) === 0o600, `the site file has mode ${(fs.statSync(site).mode & 0o777).toString(8)}`);
  // The site's client-network map, run by this nginx on a test header instead of the peer's address (which is
  // loopback here), answered on a plain port: every IPv6 spelling nginx writes must give its /64.
  const siteText = fs.readFileSync(site, 'utf8');
  const mapBlock = /\nmap \$remote_addr \$(\w+) \{([\s\S]*?)\n\}/.exec(siteText);
  check(mapBlock !== null, 'no client-network map in the site file');
  const mapPort = await freePort();
  const mapTest = mapBlock ? [
    `  map $http_x_test_address $test_network {${mapBlock[2].replace('$remote_addr;', '$http_x_test_address;')}\n  }`,
    `  server { listen 127.0.0.1:${mapPort}; access_log off; location / { return 200 "$test_network"; } }`] : [];
  fs.writeFileSync(path.join(prefix, 'nginx.conf'), [
    `pid ${prefix}/nginx.pid;`,
    `error_log ${prefix}/error.log info;`,
    'worker_processes 1;',
    'events { worker_connections 256; }',
    'http {',
    `  access_log ${prefix}/access.log;`,
    `  client_body_temp_path ${prefix}/client_body;`,
    `  proxy_temp_path ${prefix}/proxy;`,
    `  fastcgi_temp_path ${prefix}/fastcgi;`,
    `  uwsgi_temp_path ${prefix}/uwsgi;`,
    `  scgi_temp_path ${prefix}/scgi;`,
    `  include ${site};`,
    ...mapTest,
    '}', ''].join('\n'));
  const asUser = process.getuid && process.getuid() === 0 ? { uid: 65534, gid: 65534 } : {};
  if (asUser.uid !== undefined) {
    fs.chmodSync(work, 0o755);
    for (const f of fs.readdirSync(prefix)) fs.chownSync(path.join(prefix, f), asUser.uid, asUser.gid);
    fs.chownSync(prefix, asUser.uid, asUser.gid);
  }
  const args = ['-p', prefix, '-e', `${prefix}/error.log`, '-c', `${prefix}/nginx.conf`];
  const tested = spawnSync(nginxBinary, [...args, '-t'], { encoding: 'utf8', ...asUser });
  check(tested.status === 0, 'nginx -t: ' + tested.stderr);
  nginx = spawn(nginxBinary, [...args, '-g', 'daemon off;'], { stdio: ['ignore', 'inherit', 'inherit'], ...asUser });
  let up = false;
  for (let i = 0; i < 100 && !up; i++) {
    try { up = (await request(httpsPort, '/api/study', { tls: true, servername: 'localhost', headers: { Host: 'localhost' } })).status === 200; }
    catch (e) { await new Promise((r) => setTimeout(r, 100)); }
  }
  if (!up) throw new Error('nginx did not answer: ' + (fs.existsSync(`${prefix}/error.log`) ? fs.readFileSync(`${prefix}/error.log`, 'utf8') : ''));
  const base = `https://localhost:${httpsPort}/`;
  const viaNginx = (target, options = {}) => request(httpsPort, target,
    { tls: true, servername: 'localhost', ...options, headers: { Host: `localhost:${httpsPort}`, ...(options.headers || {}) } });
  const researcher = { Authorization: 'Bearer ' + TOKEN };

  // One participant session in Chromium through https:// (the self-signed certificate accepted by the context).
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true,
    args: [...FLAGS, '--host-resolver-rules=MAP localhost 127.0.0.1'] });
  const context = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1000, height: 700 } });
  const page = await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  const session = await runSession(page, base, check, 'https');
  check(page.url().startsWith('https://localhost:'), 'the session ran on ' + page.url());
  check(session.answers.size === TRIALS, `answered ${session.answers.size} trials, expected ${TRIALS}`);
  check(pageErrors.length === 0, 'page errors: ' + pageErrors.join('; '));
  await browser.close();

  // Every answer stored as pressed (export through the proxy, researcher token in the header).
  const exported = await viaNginx('/api/researcher/export?format=json', { headers: researcher });
  check(exported.status === 200, 'export through nginx: ' + exported.status);
  const rows = exported.json ? exported.json.responses : [];
  check(rows.length === TRIALS, `stored ${rows.length} responses, expected ${TRIALS}`);
  for (const r of rows) {
    const side = session.answers.get(r.trial_id);
    check(side !== undefined, `stored trial ${r.trial_id} was not answered in the browser`);
    const leftChosen = (r.is_A_selected === 1) === (r.A_on_left === 1);
    check(leftChosen === (side === 'left'), `trial ${r.trial_id} stored ${leftChosen ? 'left' : 'right'}, pressed ${side}`);
    check(/Chrome/.test(r.user_agent), `user agent "${r.user_agent}"`);
  }

  // Forwarded addresses: Chromium reached nginx from 127.0.0.1; a client on 127.0.0.5 sends its own
  // X-Forwarded-For, which nginx replaces; a direct request from 127.0.0.3 (not the proxy) spoofing the header.
  const viaProxy = await answerAll(httpsPort, { tls: true, localAddress: '127.0.0.5', limit: 1,
    headers: { Host: 'localhost', 'X-Forwarded-For': '203.0.113.9' } });
  const direct = await answerAll(serverPort, { localAddress: '127.0.0.3', limit: 1,
    headers: { 'X-Forwarded-For': '203.0.113.7' } });
  const board = await viaNginx('/api/researcher/dashboard', { headers: researcher });
  check(board.status === 200, 'dashboard through nginx: ' + board.status);
  const byObserver = new Map((board.json?.participants || []).map((p) => [p.observer, p]));
  const browserObserver = rows[0]?.observer;
  const address = (observer) => { const p = byObserver.get(observer); return p ? `${p.client_address} (${p.address_source})` : 'none'; };
  check(address(browserObserver) === '127.0.0.1 (forwarded)', `the browser's participant: address ${address(browserObserver)}`);
  check(address(viaProxy.observer) === '127.0.0.5 (forwarded)', `client on 127.0.0.5 via nginx: address ${address(viaProxy.observer)}`);
  check(address(direct.observer) === '127.0.0.3 (peer)', `direct spoofing client on 127.0.0.3: address ${address(direct.observer)}`);

  // Stimuli through the proxy: the server's caching headers unchanged, revalidation answered 304; HSTS on HTTPS.
  const image = await viaNginx('/stimuli/0.png');
  check(image.status === 200 && image.headers['content-type'] === 'image/png', 'stimulus through nginx: ' + image.status);
  check(/immutable/.test(image.headers['cache-control'] || '') && /max-age=31536000/.test(image.headers['cache-control'] || ''),
    'stimulus Cache-Control: ' + image.headers['cache-control']);
  check(/^"[0-9a-f]{64}"$/.test(image.headers.etag || ''), 'stimulus ETag: ' + image.headers.etag);
  const again = await viaNginx('/stimuli/0.png', { headers: { 'If-None-Match': image.headers.etag } });
  check(again.status === 304, 'If-None-Match through nginx: ' + again.status);
  check(/max-age=/.test(image.headers['strict-transport-security'] || ''), 'no Strict-Transport-Security header');
  // nginx refuses a body over 16 KiB itself.
  const big = await viaNginx('/api/join', { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ label: 'x'.repeat(20000) }) });
  check(big.status === 413, 'a 20 kB body through nginx: ' + big.status);

  // The client network of each address (as nginx writes addresses: RFC 5952, "::" for two or more zero groups).
  for (const [address, network] of [['2001:db8:1:2:3:4:5:6', '2001:db8:1:2'], ['2001:db8:1:2::5', '2001:db8:1:2'],
    ['2001:db8:1:0:a:b:c:d', '2001:db8:1:0'], ['2001:db8:1::b:c:d', '2001:db8:1:0'], ['2001:db8::5', '2001:db8:0:0'],
    ['2001:db8::1:2:3:4', '2001:db8:0:0'], ['2001::5:1:2:3:4', '2001:0:0:5'], ['2001::1:2', '2001:0:0:0'],
    ['192.0.2.1', '192.0.2.1']]) {
    const answer = await request(mapPort, '/', { headers: { 'X-Test-Address': address } });
    check(answer.status === 200 && answer.text === network,
      `client network of ${address}: "${answer.text}", expected ${network}`);
  }

  // The access log holds paths, never query strings (an older ?p= link, a platform's SESSION_ID) nor tokens.
  await viaNginx('/?p=0123456789abcdef0123456789abcdef&SESSION_ID=60bb1b2c3d4e5f6a7b8c9d22');
  await new Promise((r) => setTimeout(r, 300));
  const accessLog = fs.readFileSync(`${prefix}/site-access.log`, 'utf8');
  check(/"GET \/api\/study HTTP\/1\.1" 200/.test(accessLog), 'the access log lacks the requests: ' + accessLog.slice(0, 300));
  check(!accessLog.includes('?') && !accessLog.includes('0123456789abcdef0123456789abcdef') &&
    !accessLog.includes('60bb1b2c3d4e5f6a7b8c9d22'), 'a query string reached the access log');
  check(!accessLog.includes(session.token), "the participant's token reached the access log");
  exitCode = failures === 0 ? 0 : 1;
} catch (e) {
  console.error(e);
} finally {
  if (nginx) nginx.kill('SIGTERM');
  if (server) server.kill('SIGTERM');
  if (nginx && nginx.exitCode === null) await new Promise((r) => { nginx.on('exit', r); setTimeout(r, 5000); });
  removeFolder(work);
}
console.log(exitCode === 0 ? 'PASS: https session through nginx' : `FAILED (${failures} checks)`);
process.exit(exitCode);
