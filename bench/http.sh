#!/bin/sh
# archgram HTTP throughput: wrk against one model's JSON and its GLB, on a loopback archgramd
# with a temp database, signed in with an API token; and the cost of signing in: the same
# GET /api/v1/models/{id} with a token against a second archgramd without accounts
# (--no-auth), in alternating rounds so both see the same machine load. Prints figures; not a
# test.
set -eu
cd "$(dirname "$0")/.."

if ! command -v wrk >/dev/null 2>&1; then
  echo "bench/http.sh: wrk is not installed (make deps-bench installs it); skipped"
  exit 0
fi
[ -x build/archgramd ] || make --no-print-directory build/archgramd

TMP=$(mktemp -d)
PIDS=
cleanup() {
  for p in $PIDS; do
    kill -TERM "$p" 2>/dev/null || true
    wait "$p" 2>/dev/null || true
  done
  rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# Two free loopback ports (bind to port 0, read them back, release).
free_ports() {
  node -e '
    const net = require("node:net");
    const a = net.createServer().listen(0, "127.0.0.1", () => {
      const b = net.createServer().listen(0, "127.0.0.1", () => {
        console.log(a.address().port, b.address().port); a.close(); b.close();
      });
    });'
}

# start NAME ARGS...: an archgramd with the demo content; its port in $TMP/NAME.port.
start() {
  name=$1
  shift
  set -- $(free_ports) "$@"
  port=$1
  wsport=$2
  shift 2
  build/archgramd --port "$port" --ws-port "$wsport" --bind 127.0.0.1 --db "$TMP/$name.db" \
    --demo --no-web --rate-rest 0 "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  PIDS="$PIDS $!"
  pid=$!
  i=0
  until grep -q "listening on" "$TMP/$name.out"; do
    i=$((i + 1))
    if [ $i -gt 100 ] || ! kill -0 "$pid" 2>/dev/null; then
      echo "bench/http.sh: archgramd ($name) did not start:"; cat "$TMP/$name.err"; exit 1
    fi
    sleep 0.1
  done
  echo "$port" >"$TMP/$name.port"
  echo "$pid" >"$TMP/$name.pid"
}

# CPU time a process used so far, in clock ticks (user + system).
cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }

start auth
start open --no-auth
BASE=http://127.0.0.1:$(cat "$TMP/auth.port")
OPEN=http://127.0.0.1:$(cat "$TMP/open.port")
# The first start printed the admin's sign-in link with its token.
TOKEN=$(sed -n 's/.*#token=\([A-Za-z0-9._~+-]*\).*/\1/p' "$TMP/auth.out" | head -n 1)
[ -n "$TOKEN" ] || { echo "bench/http.sh: archgramd printed no admin token"; exit 1; }
AUTH="Authorization: Bearer $TOKEN"

# The first model (a demo building), for the model and GLB figures.
first_model() {
  curl -sf -H "$AUTH" "$1/api/v1/models?page_size=1" |
    node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>{const j=JSON.parse(s);console.log(j.items.length?j.items[0].id:"")})'
}
DEMO=
i=0
while [ -z "$DEMO" ] && [ $i -lt 50 ]; do
  DEMO=$(first_model "$BASE")
  [ -n "$DEMO" ] || sleep 0.1
  i=$((i + 1))
done
[ -n "$DEMO" ] || { echo "bench/http.sh: no demo model"; exit 1; }
ADMIN="$AUTH"

# For the auth overhead: the small test fixture, imported by an ordinary account that then owns
# it (so each request checks its role on the model, as most will), and the same file on the
# server without accounts.
USER_TOKEN=$(curl -sf -H "$AUTH" -H 'Content-Type: application/json' -d '{"name":"bench"}' \
  "$BASE/api/v1/users" | node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>console.log(JSON.parse(s).token))')
AUTH="Authorization: Bearer $USER_TOKEN"
import_model() { # BASE → model id
  job=$(curl -sf -X POST --data-binary @tests/data/http/two_boxes.obj -H "$AUTH" \
    -H 'Content-Type: application/octet-stream' "$1/api/v1/models?name=bench&format=obj" |
    node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>console.log(JSON.parse(s).id))')
  i=0
  until curl -sf -H "$AUTH" "$1/api/v1/jobs/$job" | grep -q '"status" *: *"succeeded"'; do
    i=$((i + 1)); [ $i -lt 300 ] || { echo "bench/http.sh: import job $job did not succeed" >&2; exit 1; }
    sleep 0.1
  done
  curl -sf -H "$AUTH" "$1/api/v1/jobs/$job" |
    node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>console.log(JSON.parse(s).result.model))'
}
MODEL=$(import_model "$BASE")
OPEN_MODEL=$(import_model "$OPEN")
[ -n "$MODEL" ] && [ -n "$OPEN_MODEL" ] || { echo "bench/http.sh: no model to measure"; exit 1; }
[ "$(curl -sf -H "$AUTH" "$BASE/api/v1/models/$MODEL" | grep -o '"role":"[a-z]*"')" = '"role":"owner"' ] ||
  { echo "bench/http.sh: the account does not own its model"; exit 1; }
GLB_BYTES=$(curl -sf -H "$ADMIN" "$BASE/api/v1/models/$DEMO/mesh.glb" | wc -c)

# wrk URL SECONDS [HEADER]: requests/s, and the line of figures in $TMP/line.
measure() {
  if [ -n "${3:-}" ]; then
    out=$(wrk -t2 -c32 -d"$2"s --latency -H "$3" "$1")
  else
    out=$(wrk -t2 -c32 -d"$2"s --latency "$1")
  fi
  rps=$(printf '%s\n' "$out" | awk '/^Requests\/sec:/ {print $2}')
  lat=$(printf '%s\n' "$out" | awk '$1 == "Latency" {print "avg " $2 ", stdev " $3 ", max " $4; exit}')
  p50=$(printf '%s\n' "$out" | awk '$1 == "50%" {print $2}')
  p99=$(printf '%s\n' "$out" | awk '$1 == "99%" {print $2}')
  errs=$(printf '%s\n' "$out" | awk '/Non-2xx|Socket errors/ {printf "%s; ", $0}')
  echo "$rps requests/s; latency $lat; p50 $p50, p99 $p99${errs:+; $errs}" >"$TMP/line"
  echo "$rps"
}

run() {
  measure "$2" 10 "$ADMIN" >/dev/null
  echo "http $1: $(cat "$TMP/line")"
}

echo "bench/http.sh: wrk -t2 -c32 against archgramd on 127.0.0.1 (model $DEMO, GLB $GLB_BYTES bytes)"
run "GET /api/v1/models/$DEMO" "$BASE/api/v1/models/$DEMO"
run "GET /api/v1/models/$DEMO/mesh.glb" "$BASE/api/v1/models/$DEMO/mesh.glb"

# Auth overhead: rounds of 5 s, alternating, medians compared. Requests/s move with whatever
# else the machine runs; the server's CPU time per request (from /proc, user + system) much
# less, so both are printed and the CPU figure is the one to hold against the target.
ROUNDS=7
HZ=$(getconf CLK_TCK)
: >"$TMP/open.rps"
: >"$TMP/auth.rps"
: >"$TMP/open.cpu"
: >"$TMP/auth.cpu"
# round NAME URL [HEADER]: requests/s to NAME.rps, server CPU microseconds per request to NAME.cpu
round() {
  pid=$(cat "$TMP/$1.pid")
  c0=$(cpu_ticks "$pid")
  rps=$(measure "$2" 5 "${3:-}")
  c1=$(cpu_ticks "$pid")
  echo "$rps" >>"$TMP/$1.rps"
  awk -v c="$((c1 - c0))" -v hz="$HZ" -v r="$rps" 'BEGIN {printf "%.1f\n", c / hz * 1e6 / (r * 5)}' >>"$TMP/$1.cpu"
}
r=0
while [ $r -lt $ROUNDS ]; do
  round open "$OPEN/api/v1/models/$OPEN_MODEL"
  round auth "$BASE/api/v1/models/$MODEL" "$AUTH"
  r=$((r + 1))
done
median() { sort -n "$1" | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
list() { tr '\n' ' ' <"$1" | sed 's/ $//'; }
change() { awk -v a="$1" -v o="$2" 'BEGIN {printf "%+.1f%%", (a / o - 1) * 100}'; }
open_rps=$(median "$TMP/open.rps")
auth_rps=$(median "$TMP/auth.rps")
open_cpu=$(median "$TMP/open.cpu")
auth_cpu=$(median "$TMP/auth.cpu")
echo "http auth overhead on GET /api/v1/models/{id}, an owner's token vs no accounts (medians of" \
  "$ROUNDS alternating 5 s rounds; target: at most 5% slower): server CPU per request" \
  "$auth_cpu us vs $open_cpu us ($(change "$auth_cpu" "$open_cpu"); rounds $(list "$TMP/auth.cpu")" \
  "vs $(list "$TMP/open.cpu")); throughput $auth_rps vs $open_rps requests/s" \
  "($(change "$auth_rps" "$open_rps"); rounds $(list "$TMP/auth.rps") vs $(list "$TMP/open.rps"))"
