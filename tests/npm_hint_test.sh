#!/usr/bin/env bash
# scripts/fetch-test-deps.sh behind a TLS-intercepting proxy: a registry with a self-signed certificate (openssl
# s_server on loopback) fails at once with npm's last lines and one line naming the fix (NODE_EXTRA_CA_CERTS or
# npm's cafile); an unreachable registry says so. Skipped (77) without npm or openssl.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
command -v npm >/dev/null 2>&1 || { echo "SKIP: npm not installed"; exit 77; }
command -v openssl >/dev/null 2>&1 || { echo "SKIP: openssl not installed"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-npm-hint.XXXXXX")
server=""
trap '[ -n "$server" ] && kill "$server" 2>/dev/null; rm -rf "$dir"' EXIT
fail() { echo "npm_hint_test: $*" >&2; exit 1; }
# A copy of the browser tests' project without node_modules, and an empty npm cache, so that npm must ask the registry.
mkdir "$dir/project"
cp "$root/tests/browser/package.json" "$root/tests/browser/package-lock.json" "$dir/project/"
openssl req -x509 -newkey rsa:2048 -nodes -keyout "$dir/key.pem" -out "$dir/cert.pem" -days 1 -subj /CN=127.0.0.1 \
  >/dev/null 2>&1
openssl s_server -accept 127.0.0.1:0 -cert "$dir/cert.pem" -key "$dir/key.pem" -www >"$dir/server.log" 2>&1 &
server=$!
port=""
for _ in $(seq 1 50); do
  port=$(sed -n 's/^ACCEPT .*:\([0-9]*\)$/\1/p' "$dir/server.log")
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || fail "openssl s_server did not start: $(cat "$dir/server.log")"
# npm's retries (about a minute for a certificate error) are switched off here; the message is the same.
unset https_proxy HTTPS_PROXY http_proxy HTTP_PROXY NODE_EXTRA_CA_CERTS
export npm_config_cache="$dir/cache" npm_config_fetch_retries=0 npm_config_proxy= npm_config_https_proxy=
export npm_config_userconfig="$dir/npmrc" TMPDIR="$dir"
start=$SECONDS
rc=0
out=$(npm_config_registry="https://127.0.0.1:$port/" bash "$root/scripts/fetch-test-deps.sh" "$dir/project" 2>&1) ||
  rc=$?
echo "$out"
[ "$rc" = 1 ] || fail "exit status $rc, not 1"
[ $((SECONDS - start)) -lt 60 ] || fail "took $((SECONDS - start)) s"
grep -q 'self-signed certificate' <<<"$out" || fail "npm's own lines are not shown"
[ "$(grep -c '^test-deps: npm could not verify the TLS certificate of https://127.0.0.1:'"$port"'/; behind a TLS-intercepting proxy, give npm the proxy.s CA: NODE_EXTRA_CA_CERTS=/path/ca.pem' <<<"$out")" = 1 ] ||
  fail "no one-line hint"
kill "$server"
server=""
# Nothing listens on port 1: unreachable.
rc=0
out=$(npm_config_registry="https://127.0.0.1:1/" bash "$root/scripts/fetch-test-deps.sh" "$dir/project" 2>&1) || rc=$?
echo "$out"
[ "$rc" = 1 ] || fail "exit status $rc, not 1"
grep -q '^test-deps: npm could not reach https://127.0.0.1:1/ (the tests need the npm registry' <<<"$out" ||
  fail "no hint for an unreachable registry"
echo "npm_hint_test: ok"
