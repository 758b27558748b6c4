#!/usr/bin/env bash
# The study server's known past defects, checked from the outside: only the command line (`skinlab stimuli build`,
# `study create`, `study serve`, `study export`, `study simulate`, `analyze scale`) and raw HTTP through curl, so the
# same script runs against any version of the binary and shows which of them still has a defect.
#
#   1. a join with an explicit label that a later bare join would be given must not lock out bare joins;
#   2. a User-Agent with ill-formed UTF-8 must not break the JSON export;
#   3. a chunked body far over the 16 KiB cap must be refused while it arrives (server peak RSS grows < 40 MiB);
#   4. a number that no double holds (1e400) is a 400, not a 500;
#   5. a CSV export with a quoted newline in a field must be read back by `analyze scale`;
#   6. a stimulus swapped for a symbolic link after `serve` started must not be served;
#   7. a request naming another host is refused (DNS rebinding);
#   8. the researcher token is not accepted in the query string;
#   9. unauthenticated joins from one address are rate-limited;
#  10. trial ids of two participants are not consecutive integers;
#  11. `study simulate` interrupted and run again resumes instead of failing with "label taken".
#  12. a platform id alone (no join key, no platform session id) does not hand out that participant's token;
#  13. one platform id in another letter case is not a second participant;
#  14. one token cannot start sessions without bound;
#  15. joins from many addresses of one IPv6 /64 share one allowance;
#  16. the participant token is not accepted in the URL;
#  17. study.db, its backup and the nginx site file are readable by their owner only;
#  18. the researcher token can come from a file (not the command line, not printed);
#  19. every answer forbids framing;
#  20. a body in a transfer coding other than chunked is refused, not read as empty (request smuggling);
#  21. a label that a spreadsheet would run as a formula is exported as text;
#  22. the nginx redirect goes to the configured name, on the addresses asked for only, and the access log holds
#      no query strings.
#
# Usage: server_defects_test.sh SKINLAB_CLI SOURCE_DIR. Prints one PASS/FAIL line per check and exits 1 if any
# failed; exits 77 (skipped) when curl, jq or sqlite3 is missing or no EGL renderer works.
set -uo pipefail

SKINLAB="$1"
SOURCE_DIR="$2"
SPEC="$SOURCE_DIR/tests/data/stimuli/cluster-small.toml"

skip() {
  echo "SKIPPED: $*"
  exit 77
}
command -v curl >/dev/null || skip "curl not found (scripts/install-deps.sh installs it)"
command -v jq >/dev/null || skip "jq not found (scripts/install-deps.sh installs it)"
command -v sqlite3 >/dev/null || skip "sqlite3 not found (scripts/install-deps.sh installs it)"

WORK=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-defects.XXXXXX")
SERVER_PID=""
failures=0
finish() {
  [ -n "$SERVER_PID" ] && kill "$SERVER_PID" 2>/dev/null && wait "$SERVER_PID" 2>/dev/null
  if [ "$failures" = 0 ]; then rm -rf "$WORK"; else echo "files kept in $WORK"; fi
}
trap finish EXIT

check() { # NAME CONDITION-EXIT-STATUS DETAIL
  if [ "$2" = 0 ]; then
    echo "PASS: $1 [$SECONDS s]"
  else
    echo "FAIL: $1 ($3)"
    failures=$((failures + 1))
  fi
}

# A small stimulus set (12 images, no SSS) and a study over it.
if ! "$SKINLAB" stimuli build "$SPEC" -o "$WORK/stimuli" --no-contact-sheet >"$WORK/build.log" 2>&1; then
  grep -q "no usable EGL" "$WORK/build.log" && skip "no EGL renderer: $(tail -n 1 "$WORK/build.log")"
  cat "$WORK/build.log"
  echo "FAIL: the stimulus build failed"
  exit 1
fi
cat >"$WORK/design.toml" <<'EOF'
title = "Server defects"
seed = 5
condition_factor = "camera.yaw_deg"
blocks = ["builtin:head/close"]
repetitions = 1

[practice]
trials = 0

[catch]
blank = 0
EOF

echo '{"0.0": 0, "20.0": 0.5, "40.0": 1, "60.0": 1.5}' >"$WORK/truth.json"

start_server() { # DB [extra serve options...]
  local db="$1"
  shift
  # Emptied here, before the server starts: the redirection below runs in the background, so until then the loop
  # would read the previous server's address.
  : >"$WORK/serve.log"
  "$SKINLAB" study serve "$db" --port 0 --token researcher-secret-token "$@" >"$WORK/serve.log" 2>&1 &
  SERVER_PID=$!
  for _ in $(seq 1 100); do
    URL=$(grep -o 'http://127\.0\.0\.1:[0-9]*' "$WORK/serve.log" | head -n 1)
    [ -n "$URL" ] && return 0
    sleep 0.1
  done
  cat "$WORK/serve.log"
  echo "FAIL: the server did not start"
  exit 1
}
stop_server() {
  kill "$SERVER_PID" 2>/dev/null
  wait "$SERVER_PID" 2>/dev/null
  SERVER_PID=""
}
post() { # PATH JSON [curl options...] -> body, then the status on its own last line
  local path="$1" body="$2"
  shift 2
  curl -s -w '\n%{http_code}' -H 'Content-Type: application/json' --data-binary "$body" "$@" "$URL$path"
}
status_of() { tail -n 1; }
body_of() { sed '$d'; }

"$SKINLAB" study create --stimuli "$WORK/stimuli" --design "$WORK/design.toml" -o "$WORK/study.db" \
  >"$WORK/create.log" 2>&1 || { cat "$WORK/create.log"; echo "FAIL: study create"; exit 1; }
start_server "$WORK/study.db"

# 1. The label squat.
for _ in 1 2 3 4 5; do post /api/join '{}' >/dev/null; done
post /api/join '{"label":"P007"}' >/dev/null
code=$(post /api/join '{}' | status_of)
[ "$code" = 201 ]
check "a bare join after an explicit label P007 is accepted" $? "status $code"

# 2. Ill-formed UTF-8 in a stored header.
# (the User-Agent is stored with each session: one with bytes ff fe, one valid but cut mid-character at byte 512)
ua_token=$(post /api/join '{"label":"ua"}' | body_of | jq -r .token)
session_body="{\"token\":\"$ua_token\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}"
reply=$(post /api/session "$session_body" -H $'User-Agent: Mozilla \xff\xfe broken')
ua_session=$(echo "$reply" | body_of | jq -r .session)
ua_trial=$(echo "$reply" | body_of | jq -r .trial.id)
post /api/response "{\"token\":\"$ua_token\",\"session\":$ua_session,\"trial\":$ua_trial,\"side\":\"left\",\"response_ms\":900,\"client_time\":\"t\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}" \
  -H $'User-Agent: Mozilla \xff\xfe broken' >/dev/null
post /api/session "$session_body" -H "User-Agent: a$(printf 'é%.0s' $(seq 1 300))" >/dev/null
stop_server
"$SKINLAB" study export "$WORK/study.db" --format json -o "$WORK/export.json" >"$WORK/export.log" 2>&1 &&
  jq empty "$WORK/export.json" 2>/dev/null
check "the JSON export survives a User-Agent with bytes ff fe" $? "$(tail -n 1 "$WORK/export.log")"
start_server "$WORK/study.db"

# 3. A chunked flood: 96 MiB, chunked.
peak() { awk '/VmHWM/ {print $2}' "/proc/$SERVER_PID/status"; }
before=$(peak)
head -c $((96 * 1024 * 1024)) /dev/zero |
  curl -s -o /dev/null -m 60 -H 'Content-Type: application/json' -H 'Transfer-Encoding: chunked' \
    --data-binary @- "$URL/api/join" 2>/dev/null
after=$(peak)
grown=$(((after - before) / 1024))
[ "$grown" -lt 40 ]
check "a 96 MiB chunked body is refused while it arrives" $? "peak RSS grew by $grown MiB"

# 4. A number that overflows a double.
reply=$(post /api/join '{"label":"q1"}')
token=$(echo "$reply" | body_of | jq -r .token)
reply=$(post /api/session "{\"token\":\"$token\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}")
session=$(echo "$reply" | body_of | jq -r .session)
code=$(post /api/response "{\"token\":\"$token\",\"session\":$session,\"trial\":1e400,\"side\":\"left\",\"response_ms\":900,\"client_time\":\"t\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}" | status_of)
[ "$code" = 400 ]
check "trial 1e400 gets 400" $? "status $code"

# 10. Trial ids of two participants.
first=$(echo "$reply" | body_of | jq -r .trial.id)
reply2=$(post /api/join '{"label":"q2"}')
token2=$(echo "$reply2" | body_of | jq -r .token)
second=$(post /api/session "{\"token\":\"$token2\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}" |
  body_of | jq -r .trial.id)
if [[ "$first" =~ ^[0-9]+$ && "$second" =~ ^[0-9]+$ ]]; then
  difference=$((second - first))
  [ "${difference#-}" -gt 1000 ]
else
  false
fi
check "trial ids of consecutive participants are not guessable" $? "ids $first and $second"

# 5. A quoted newline in a CSV field: answers, then condition names with a newline (a design may use any text;
#    set in the study file, as a researcher's manifest could), the CSV export read back by analyze scale.
timeout 120 "$SKINLAB" study simulate "$WORK/study.db" --url "$URL" --observer-count 3 --seed 2 --label-prefix sim \
  --truth "$WORK/truth.json" >"$WORK/simulate1.log" 2>&1
stop_server
cp "$WORK/study.db" "$WORK/renamed.db"
sqlite3 "$WORK/renamed.db" "UPDATE trials SET condition_a = 'two' || char(10) || 'lines' WHERE condition_a = '0.0';
  UPDATE trials SET condition_b = 'two' || char(10) || 'lines' WHERE condition_b = '0.0';"
"$SKINLAB" study export "$WORK/renamed.db" --format csv -o "$WORK/export.csv" >"$WORK/export-csv.log" 2>&1
grep -q '"two$' "$WORK/export.csv"
check "the CSV export quotes a field with a newline" $? "no quoted newline in the export"
timeout 120 "$SKINLAB" analyze scale "$WORK/export.csv" -o "$WORK/scale" >"$WORK/scale.log" 2>&1
check "analyze scale reads that CSV export back" $? "$(tail -n 1 "$WORK/scale.log")"
start_server "$WORK/study.db"

# 11. simulate, run again with the same observers (as after an interruption), resumes.
timeout 120 "$SKINLAB" study simulate "$WORK/study.db" --url "$URL" --observer-count 3 --seed 2 --label-prefix sim --truth "$WORK/truth.json" \
  >"$WORK/simulate2.log" 2>&1
check "study simulate run again resumes" $? "$(tail -n 1 "$WORK/simulate2.log")"

# 7. Another host.
code=$(curl -s -o /dev/null -w '%{http_code}' -H 'Host: attacker.example' "$URL/api/study")
[ "${code:0:1}" = 4 ]
check "a request for Host attacker.example is refused" $? "status $code"

# 8. The researcher token in the query string.
code=$(curl -s -o /dev/null -w '%{http_code}' "$URL/api/researcher/status?token=researcher-secret-token")
[ "$code" = 401 ] || [ "$code" = 400 ]
check "the researcher token in the URL is refused" $? "status $code"

# 6. A stimulus swapped for a symbolic link after the server started.
image=$(find "$WORK/stimuli" -name '*.png' ! -name 'contact*' | sort | head -n 1)
sha_before=$(sha256sum "$image" | cut -d' ' -f1)
echo "not the verified image" >"$WORK/other.png"
mv "$image" "$image.orig" && ln -s "$WORK/other.png" "$image"
served_ok=1
for n in $(seq 0 11); do
  sha=$(curl -s "$URL/stimuli/$n.png" | sha256sum | cut -d' ' -f1)
  [ "$sha" = "$(sha256sum "$WORK/other.png" | cut -d' ' -f1)" ] && served_ok=0
done
[ "$served_ok" = 1 ]
check "a stimulus swapped for a link is not served" $? "the link's target was served (verified sha256 $sha_before)"
rm "$image" && mv "$image.orig" "$image"

# 21. A label that a spreadsheet runs as a formula.
formula_token=$(post /api/join '{"label":"-2-3"}' | body_of | jq -r .token)
reply=$(post /api/session "{\"token\":\"$formula_token\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}")
f_session=$(echo "$reply" | body_of | jq -r .session)
f_trial=$(echo "$reply" | body_of | jq -r .trial.id)
post /api/response "{\"token\":\"$formula_token\",\"session\":$f_session,\"trial\":$f_trial,\"side\":\"left\",\"response_ms\":900,\"client_time\":\"t\",\"viewport_width\":1280,\"viewport_height\":720,\"device_pixel_ratio\":1}" >/dev/null
"$SKINLAB" study export "$WORK/study.db" --format csv -o "$WORK/formula.csv" >/dev/null 2>&1
grep -q "^'-2-3," "$WORK/formula.csv" && ! grep -q '^-2-3,' "$WORK/formula.csv"
check "a -2-3 label is exported as text" $? "$(grep -m 1 -- '2-3,' "$WORK/formula.csv")"

# 9. Join flood: 150 joins from one address over one kept-alive connection (the limit lets 60 through at once,
#    then one a second).
urls=()
for _ in $(seq 1 150); do urls+=("$URL/api/join"); done
accepted=$(curl -s -w '\n%{http_code}\n' -H 'Content-Type: application/json' --data-binary '{}' "${urls[@]}" |
  grep -c '^201$')
[ "$accepted" -lt 150 ]
check "150 joins in a row from one address are rate-limited" $? "$accepted accepted"

# 16. The participant token in the URL (the participant of check 2).
code=$(curl -s -o /dev/null -w '%{http_code}' "$URL/api/state?token=$ua_token")
[ "$code" != 200 ]
check "the participant token in the URL is refused" $? "status $code"

# 14. One token, many sessions.
codes=""
for _ in $(seq 1 40); do codes+=" $(post /api/session "$session_body" | status_of)"; done
[[ "$codes" == *429* ]]
check "40 sessions for one token are not all accepted" $? "statuses:$codes"

# 19. Framing.
headers=$(curl -s -D - -o /dev/null "$URL/")
grep -qi '^X-Frame-Options: DENY' <<<"$headers" && grep -qi "frame-ancestors 'none'" <<<"$headers"
check "the page forbids framing" $? "$(tr -d '\r' <<<"$headers" | tr '\n' ' ')"

# 20. Transfer-Encoding: identity with a second request in its body: one answer (a refusal), never two.
port=${URL##*:}
smuggled=$'POST /api/join HTTP/1.1\r\nHost: 127.0.0.1:'"$port"$'\r\nContent-Type: application/json\r\nContent-Length: 2\r\n\r\n{}'
exec 3<>"/dev/tcp/127.0.0.1/$port"
printf 'POST /api/join HTTP/1.1\r\nHost: 127.0.0.1:%s\r\nContent-Type: application/json\r\nTransfer-Encoding: identity\r\n\r\n%s' \
  "$port" "$smuggled" >&3
answers=$(timeout 4 cat <&3 | grep -ao 'HTTP/1\.1 [0-9][0-9][0-9]' | wc -l)
exec 3<&-
[ "$answers" = 1 ]
check "Transfer-Encoding: identity with a request in the body gets one answer" $? "$answers answers"

stop_server

# 17. Private files (created under the usual umask 022).
(
  umask 022
  "$SKINLAB" study create --stimuli "$WORK/stimuli" --design "$WORK/design.toml" -o "$WORK/private.db" >/dev/null 2>&1
  "$SKINLAB" study backup "$WORK/private.db" "$WORK/private-backup.db" >/dev/null 2>&1
  echo "-----BEGIN CERTIFICATE-----" >"$WORK/cert.pem"
  "$SKINLAB" study deploy-config --server-name study.example.org --upstream 127.0.0.1:8080 --cert "$WORK/cert.pem" \
    --key "$WORK/cert.pem" --redirect-port 80 --listen 192.0.2.10:443 -o "$WORK/site.conf" >/dev/null 2>&1
)
modes=$(stat -c '%a' "$WORK/private.db" "$WORK/private-backup.db" "$WORK/site.conf" 2>&1 | tr '\n' ' ')
[ "$modes" = "600 600 600 " ]
check "study.db, a backup and the nginx site file are created 0600" $? "modes $modes"

# 22. The nginx site: redirect target, addresses, access log.
grep -q 'return 301 https://study.example.org$request_uri;' "$WORK/site.conf" &&
  ! grep -q '\$host\$request_uri' "$WORK/site.conf" && ! grep -Eq 'listen (\[::\]:)?(80|443)( |;)' "$WORK/site.conf" &&
  grep -q 'access_log .*_private;' "$WORK/site.conf" && grep -q '"$request_method $uri ' "$WORK/site.conf"
check "the nginx redirect names the server, listens where asked, logs no query strings" $? \
  "$(grep -E 'return 301|listen|access_log' "$WORK/site.conf" | tr -s ' ' | tr '\n' ';')"

# 18. The researcher token from a file.
printf 'file-token-%s\n' "$RANDOM$RANDOM$RANDOM" >"$WORK/token"
file_token=$(head -n 1 "$WORK/token")
: >"$WORK/serve.log" # (as in start_server)
"$SKINLAB" study serve "$WORK/study.db" --port 0 --token-file "$WORK/token" >"$WORK/serve.log" 2>&1 &
SERVER_PID=$!
URL=""
for _ in $(seq 1 100); do
  URL=$(grep -o 'http://127\.0\.0\.1:[0-9]*' "$WORK/serve.log" | head -n 1)
  [ -n "$URL" ] && break
  sleep 0.1
done
code=$(curl -s -o /dev/null -w '%{http_code}' -H "Authorization: Bearer $file_token" "$URL/api/researcher/status")
[ "$code" = 200 ] && ! grep -q "$file_token" "$WORK/serve.log" && ! tr '\0' ' ' <"/proc/$SERVER_PID/cmdline" | grep -q "$file_token"
check "the researcher token from --token-file works, unprinted and not on the command line" $? "status $code"
stop_server

# 12, 13, 15. A study recruiting on MTurk, served behind a "proxy" (this script, from 127.0.0.1).
cp "$WORK/design.toml" "$WORK/mturk.toml"
printf '\n[recruitment]\nplatform = "mturk"\n' >>"$WORK/mturk.toml"
"$SKINLAB" study create --stimuli "$WORK/stimuli" --design "$WORK/mturk.toml" -o "$WORK/mturk.db" >/dev/null 2>&1
start_server "$WORK/mturk.db" --trusted-proxy 127.0.0.1 --joins-per-minute 5
worker_token=$(post /api/join '{"join_key":"worker-browser-key","recruitment":{"workerId":"A1B2C3D4E5F6","assignmentId":"3ASSIGNMENTAAAAAAAAAAAAAAAAA"}}' \
  -H 'X-Forwarded-For: 198.51.100.1' | body_of | jq -r .token)
reply=$(post /api/join '{"recruitment":{"workerId":"A1B2C3D4E5F6"}}' -H 'X-Forwarded-For: 198.51.100.2')
[ -n "$worker_token" ] && [ "$worker_token" != null ] && ! grep -q "$worker_token" <<<"$reply"
check "a worker id alone does not hand out the worker's token" $? "$(tr '\n' ' ' <<<"$reply")"
post /api/join '{"join_key":"other-browser-key","recruitment":{"workerId":"a1b2c3d4e5f6","assignmentId":"3ASSIGNMENTBBBBBBBBBBBBBBBBB"}}' \
  -H 'X-Forwarded-For: 198.51.100.3' >/dev/null
count=$(sqlite3 "$WORK/mturk.db" "SELECT COUNT(*) FROM recruitment WHERE upper(external_id) = 'A1B2C3D4E5F6'")
[ "$count" = 1 ]
check "a worker id in lower case is the same participant" $? "$count participants"
accepted=0
for n in $(seq 1 10); do
  code=$(post /api/join "{\"recruitment\":{\"workerId\":\"W1000000000$n\"}}" -H "X-Forwarded-For: 2001:db8:1:2::$n" |
    status_of)
  [ "$code" = 201 ] && accepted=$((accepted + 1))
done
[ "$accepted" -le 5 ]
check "10 joins from one IPv6 /64 share one allowance (burst 5)" $? "$accepted accepted"

stop_server
echo "$failures check(s) failed"
[ "$failures" = 0 ]
