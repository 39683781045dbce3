#!/bin/sh
# archgram HTTP throughput: wrk against one model's JSON and its GLB, on a loopback
# archgramd with a temp database. Prints figures; not a test.
set -eu
cd "$(dirname "$0")/.."

if ! command -v wrk >/dev/null 2>&1; then
  echo "bench/http.sh: wrk is not installed (make deps-bench installs it); skipped"
  exit 0
fi
[ -x build/archgramd ] || make --no-print-directory build/archgramd

TMP=$(mktemp -d)
PID=
cleanup() {
  if [ -n "$PID" ]; then
    kill -TERM "$PID" 2>/dev/null || true
    wait "$PID" 2>/dev/null || true
  fi
  rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# Two free loopback ports (bind to port 0, read them back, release).
PORTS=$(node -e '
  const net = require("node:net");
  const a = net.createServer().listen(0, "127.0.0.1", () => {
    const b = net.createServer().listen(0, "127.0.0.1", () => {
      console.log(a.address().port, b.address().port); a.close(); b.close();
    });
  });')
set -- $PORTS
PORT=$1
WSPORT=$2
BASE=http://127.0.0.1:$PORT

build/archgramd --port "$PORT" --ws-port "$WSPORT" --bind 127.0.0.1 --db "$TMP/bench.db" --demo \
  >"$TMP/out" 2>"$TMP/err" &
PID=$!
i=0
until grep -q "listening on" "$TMP/out"; do
  i=$((i + 1))
  if [ $i -gt 100 ] || ! kill -0 "$PID" 2>/dev/null; then
    echo "bench/http.sh: archgramd did not start:"; cat "$TMP/err"; exit 1
  fi
  sleep 0.1
done

# The first model: a demo building when --demo made one, else the small test fixture.
first_model() {
  curl -sf "$BASE/api/v1/models?page_size=1" |
    node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>{const j=JSON.parse(s);console.log(j.items.length?j.items[0].id:"")})'
}
MODEL=
i=0
while [ -z "$MODEL" ] && [ $i -lt 50 ]; do
  MODEL=$(first_model)
  [ -n "$MODEL" ] || sleep 0.1
  i=$((i + 1))
done
if [ -z "$MODEL" ]; then
  JOB=$(curl -sf -X POST --data-binary @tests/data/http/two_boxes.obj \
    -H 'Content-Type: application/octet-stream' "$BASE/api/v1/models?name=bench&format=obj" |
    node -e 'let s="";process.stdin.on("data",c=>s+=c).on("end",()=>console.log(JSON.parse(s).id))')
  i=0
  until curl -sf "$BASE/api/v1/jobs/$JOB" | grep -q '"status" *: *"succeeded"'; do
    i=$((i + 1)); [ $i -lt 300 ] || { echo "bench/http.sh: import job $JOB did not succeed"; exit 1; }
    sleep 0.1
  done
  MODEL=$(first_model)
fi
GLB_BYTES=$(curl -sf "$BASE/api/v1/models/$MODEL/mesh.glb" | wc -c)

run() {
  label=$1
  url=$2
  out=$(wrk -t2 -c32 -d10s --latency "$url")
  rps=$(printf '%s\n' "$out" | awk '/^Requests\/sec:/ {print $2}')
  lat=$(printf '%s\n' "$out" | awk '$1 == "Latency" {print "avg " $2 ", stdev " $3 ", max " $4; exit}')
  p50=$(printf '%s\n' "$out" | awk '$1 == "50%" {print $2}')
  p99=$(printf '%s\n' "$out" | awk '$1 == "99%" {print $2}')
  errs=$(printf '%s\n' "$out" | awk '/Non-2xx|Socket errors/ {printf "%s; ", $0}')
  echo "http $label: $rps requests/s; latency $lat; p50 $p50, p99 $p99${errs:+; $errs}"
}

echo "bench/http.sh: wrk -t2 -c32 -d10s against archgramd on 127.0.0.1:$PORT (model $MODEL, GLB $GLB_BYTES bytes)"
run "GET /api/v1/models/$MODEL" "$BASE/api/v1/models/$MODEL"
run "GET /api/v1/models/$MODEL/mesh.glb" "$BASE/api/v1/models/$MODEL/mesh.glb"
