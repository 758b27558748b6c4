#!/usr/bin/env bash
# Fetches what the tests download, before anything is built (scripts/test.sh runs it right after the packages), so
# that a blocked network fails within the first minutes: the browser tests' npm packages (tests/browser,
# playwright-core as package-lock.json pins it) from the npm registry (`npm config get registry`). On failure it
# shows npm's last lines and one line saying what to do.
#   scripts/fetch-test-deps.sh [DIR]   DIR: the npm project folder (default tests/browser)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/progress.sh
dir="${1:-tests/browser}"
[ -f "$dir/package.json" ] || exit 0
if ! command -v npm >/dev/null 2>&1; then
  echo "test-deps: npm not found (scripts/install-deps.sh all installs it)" >&2
  exit 1
fi
registry=$(npm config get registry 2>/dev/null || echo "the npm registry")
log="$(mktemp "${TMPDIR:-/tmp}/skinlab-npm.XXXXXX.log")"
echo "test-deps: npm install in $dir from $registry (the browser tests' playwright-core; npm's log: $log)"
npm_install() { cd "$dir" && npm install --no-audit --no-fund --no-update-notifier --loglevel=error; }
if run_with_progress test-deps "$log" - npm_install; then
  echo "test-deps: done"
  exit 0
fi
tail -n 15 "$log" >&2
ca="behind a TLS-intercepting proxy, give npm the proxy's CA: NODE_EXTRA_CA_CERTS=/path/ca.pem ./scripts/test.sh (or npm config set cafile /path/ca.pem)"
if grep -qiE 'certificate|SELF_SIGNED|UNABLE_TO_(GET|VERIFY)|CERT_' "$log"; then
  echo "test-deps: npm could not verify the TLS certificate of $registry; $ca" >&2
elif grep -qE 'ECONNREFUSED|ENOTFOUND|EAI_AGAIN|ETIMEDOUT|ECONNRESET|ENETUNREACH|EHOSTUNREACH' "$log"; then
  echo "test-deps: npm could not reach $registry (the tests need the npm registry: set https_proxy, or npm config set registry URL for a mirror; $ca)" >&2
else
  echo "test-deps: npm install failed in $dir (npm's last lines are above; the whole log: $log; $ca)" >&2
fi
exit 1
