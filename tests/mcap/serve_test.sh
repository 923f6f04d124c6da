#!/usr/bin/env bash
# pmuctl serve (docs/interface.md section 9.2) against pmu-service on the simulated bus.
#   serve_test.sh PMU-SERVICE PMUCTL SOURCE-DIR foxglove|slow|tls|cli
# foxglove: Foxglove's own client (serve_client.mjs check) reads serverInfo, the channels and
#           their schemas, and pmu/voltages, pmu/health, pmu/battery equal to `pmuctl watch
#           --json`, on the server's clock (capability time); a client offering only
#           foxglove.sdk.v1 is served; a client without the subprotocol is refused (400), and
#           pages of origins not allowed (403); SIGINT stops it with 0.
# slow:     a client that never reads (ws_raw.py slow) has its messages dropped, named on
#           stderr, while a normal client keeps receiving at the full rate.
# tls:      wss:// with a self-signed certificate made now: Foxglove's client, verifying it,
#           reads live messages; plain ws:// on every interface warns about https pages.
# cli:      a port in use (exit 1, address:port named), bad --port/--listen/--client-queue/
#           --allow-origin, TLS files missing, not PEM or not matching (exit 2). Needs no
#           Node.js.
set -uo pipefail
svc=$1 ctl=$2 src=$3 mode=$4
here="$(cd "$(dirname "$0")" && pwd)"
if [ "$mode" != cli ]; then
  . "$here/mcap_env.sh"
  for p in @foxglove/ws-protocol ws; do
    [ -d "$here/node_modules/$p" ] || { echo "SKIP: $p is not installed in tests/mcap (scripts/setup.sh runs npm ci)"; exit 77; }
  done
fi
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
# Waits until the server's stderr says it serves (or it exited); false after 20 s.
wait_serving() {
  for _ in $(seq 200); do
    grep -q "serving .* on wss\?://" "$1" && return 0
    kill -0 "$2" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
# SIGINT (or the signal given), then the exit status must be 0 and the last line say it stopped.
stop_server() {
  kill -"${3:-INT}" "$1"
  wait "$1"; local status=$?
  [ $status -eq 0 ] || fail "serve exited $status after SIG${3:-INT}: $(tail -n 5 "$2")"
  grep -q "pmuctl serve: stopped; " "$2" || fail "no final line: $(tail -n 5 "$2")"
}

case "$mode" in
foxglove)
  "$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
  pids+=($!)
  port=$(free_port)
  "$ctl" --domain "$domain" serve --port "$port" --allow-origin https://viz.example.com:8443 2>"$work/serve.err" &
  server=$!; pids+=($server)
  wait_serving "$work/serve.err" "$server" || { fail "serve did not start: $(cat "$work/serve.err")"; exit 1; }

  # Pages: the defaults and --allow-origin's are let in, others refused with 403 and a line
  # that says how to allow them.
  for origin in https://app.foxglove.dev file:// http://localhost:8080 http://127.0.0.1 "http://[::1]:5173" \
                https://viz.example.com:8443; do
    line=$(python3 "$here/ws_raw.py" "$port" origin "$origin")
    [[ "$line" == "HTTP/1.1 101 "* ]] || fail "a page of $origin got: $line"
  done
  for origin in https://evil.example null https://viz.example.com http://192.168.1.10:8080; do
    line=$(python3 "$here/ws_raw.py" "$port" origin "$origin")
    [[ "$line" == "HTTP/1.1 403 "* ]] || fail "a page of $origin got: $line"
  done
  grep -q "refused 127.0.0.1:[0-9]*: origin https://evil.example is not allowed (pmuctl serve --allow-origin https://evil.example allows it)" "$work/serve.err" ||
    fail "no origin refusal line: $(cat "$work/serve.err")"
  grep -q "refused 127.0.0.1:[0-9]*: origin null is not allowed (it is no scheme://host\[:port\] origin; only --allow-origin '\*' allows it)" "$work/serve.err" ||
    fail "no refusal line for origin null: $(cat "$work/serve.err")"

  # The Foxglove SDK's name of the protocol, offered alone.
  python3 "$here/ws_raw.py" "$port" sdk || fail "a client offering foxglove.sdk.v1"
  grep -q "client 127.0.0.1:[0-9]* connected (foxglove.sdk.v1)" "$work/serve.err" || fail "no sdk connect line"

  line=$(python3 "$here/ws_raw.py" "$port" no-subprotocol)
  [[ "$line" == "HTTP/1.1 400 "* ]] || fail "a client without the subprotocol got: $line"
  grep -q "refused 127.0.0.1:[0-9]*: it does not offer the WebSocket subprotocol foxglove.websocket.v1" "$work/serve.err" ||
    fail "no refusal line: $(cat "$work/serve.err")"

  # pmuctl watch over the same seconds: the values the client must find in its messages.
  "$ctl" --domain "$domain" --json --timeout 10 watch >"$work/watch.jsonl" 2>"$work/watch.err" &
  watcher=$!; pids+=($watcher)
  sleep 2  # serve has pmu/info and pmu/config by now: the client is a late joiner
  node "$here/serve_client.mjs" "ws://127.0.0.1:$port" check "$work/watch.jsonl" 6 || fail "serve_client check"
  wait "$watcher"
  grep -q "client 127.0.0.1:[0-9]* connected (foxglove.websocket.v1)" "$work/serve.err" || fail "no connect line"
  grep -q "client 127.0.0.1:[0-9]* disconnected" "$work/serve.err" || fail "no disconnect line"
  stop_server "$server" "$work/serve.err"
  ;;

slow)
  # 40 PMUs at 10 packets/s each: 2000 samples/s, enough to fill a small queue at once.
  {
    echo "buses:"
    echo "  - interface: sim"
    echo "    name: sim0"
    echo "    devices:"
    for a in $(seq 1 40); do echo "      - {address: $a, period: 0.1}"; done
  } >"$work/fast.yaml"
  "$svc" --config "$work/fast.yaml" --domain "$domain" --log-level warn >"$work/service.log" 2>&1 &
  pids+=($!)
  port=$(free_port)
  "$ctl" --domain "$domain" serve --port "$port" --client-queue 64 2>"$work/serve.err" &
  server=$!; pids+=($server)
  wait_serving "$work/serve.err" "$server" || { fail "serve did not start: $(cat "$work/serve.err")"; exit 1; }
  sleep 2  # discovery: the samples flow before the clients come
  python3 "$here/ws_raw.py" "$port" slow 8 >"$work/slow.out" 2>&1 &
  slow=$!; pids+=($slow)
  node "$here/serve_client.mjs" "ws://127.0.0.1:$port" count 7 "$work/count.json" || fail "normal client"
  wait "$slow" || fail "slow client: $(cat "$work/slow.out")"
  sleep 1
  cat "$work/slow.out"
  # The normal client got pmu/voltages of 40 PMUs at 10/s every second (at least a quarter of
  # that on a loaded machine), the slow one notwithstanding.
  node -e '
    const r = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
    const full = r.per_second.slice(1, -1);  // whole seconds only
    const low = full.filter((n) => n < 100);  // 400 expected; a stall gives 0
    if (full.length < 5 || low.length) { console.error(`per second: ${r.per_second}`); process.exit(1); }' \
    "$work/count.json" || fail "the normal client did not keep receiving"
  grep -q "client 127.0.0.1:[0-9]* is not reading (.* queued): dropping its messages" "$work/serve.err" ||
    fail "no line saying the slow client's messages are dropped: $(cat "$work/serve.err")"
  grep -Eq "client 127.0.0.1:[0-9]+ disconnected; [1-9][0-9]* messages were dropped for it" "$work/serve.err" ||
    fail "no line with the count dropped: $(cat "$work/serve.err")"
  # SIGTERM while a client that does not read is still connected: it is not waited for long.
  python3 "$here/ws_raw.py" "$port" slow 60 >/dev/null 2>&1 &
  pids+=($!)
  sleep 3
  start=$(date +%s)
  stop_server "$server" "$work/serve.err" TERM
  [ $(($(date +%s) - start)) -le 5 ] || fail "SIGTERM took $(($(date +%s) - start)) s with a stuck client"
  grep -Eq "stopped; [0-9]+ clients?, [1-9][0-9]* messages forwarded, [1-9][0-9]* dropped" "$work/serve.err" ||
    fail "final counts: $(tail -n 1 "$work/serve.err")"
  grep -q "publish_failures\|refused" "$work/service.log" && fail "the service could not publish: $(grep -m3 "refused" "$work/service.log")"
  ;;

tls)
  "$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
  pids+=($!)
  openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=127.0.0.1 -addext subjectAltName=IP:127.0.0.1 \
    -keyout "$work/key.pem" -out "$work/cert.pem" 2>/dev/null || { fail "openssl req"; exit 1; }
  port=$(free_port)
  "$ctl" --domain "$domain" serve --port "$port" --tls-cert "$work/cert.pem" --tls-key "$work/key.pem" 2>"$work/serve.err" &
  server=$!; pids+=($server)
  wait_serving "$work/serve.err" "$server" || { fail "serve did not start: $(cat "$work/serve.err")"; exit 1; }
  grep -q "serving .* on wss://127.0.0.1:$port " "$work/serve.err" || fail "start line: $(cat "$work/serve.err")"
  SERVE_TLS_CA="$work/cert.pem" node "$here/serve_client.mjs" "wss://127.0.0.1:$port" first 30 || fail "wss client"
  # A plain ws:// client gets no WebSocket from a wss:// server.
  line=$(python3 "$here/ws_raw.py" "$port" origin http://localhost 2>&1 | head -1)
  [[ "$line" == "HTTP/1.1 101 "* ]] && fail "a plain client was served on wss://"
  stop_server "$server" "$work/serve.err"
  # Plain ws:// on every interface: https pages cannot connect, said at start.
  port=$(free_port)
  "$ctl" --domain "$domain" serve --listen 0.0.0.0 --port "$port" 2>"$work/plain.err" &
  server=$!; pids+=($server)
  wait_serving "$work/plain.err" "$server" || { fail "serve did not start: $(cat "$work/plain.err")"; exit 1; }
  grep -q "warning: ws://0.0.0.0:$port is plain WebSocket: a page served over https (the Foxglove web app) may not connect to it (mixed content).*--tls-cert and --tls-key" "$work/plain.err" ||
    fail "no mixed-content warning: $(cat "$work/plain.err")"
  stop_server "$server" "$work/plain.err"
  grep -q "warning" "$work/serve.err" && fail "a warning with TLS: $(cat "$work/serve.err")"
  ;;

cli)
  # A listener holds a port (it picks a free one and says which).
  python3 -c 'import socket,time; s=socket.socket(); s.bind(("127.0.0.1",0)); s.listen(); print(s.getsockname()[1], flush=True); time.sleep(60)' >"$work/held" &
  pids+=($!)
  for _ in $(seq 50); do [ -s "$work/held" ] && break; sleep 0.1; done
  port=$(cat "$work/held")
  timeout 20 "$ctl" --domain "$domain" serve --port "$port" 2>"$work/err"; status=$?
  [ $status -eq 1 ] && grep -q "pmuctl serve: cannot listen on 127.0.0.1:$port: Address already in use" "$work/err" ||
    fail "port in use: exit $status, $(cat "$work/err")"
  check_refused() {  # ARGS... -- the message
    local want=$1; shift
    timeout 20 "$ctl" --domain "$domain" serve "$@" 2>"$work/err"; local status=$?
    [ $status -eq 2 ] && grep -qF -- "$want" "$work/err" || fail "serve $*: exit $status, $(cat "$work/err")"
  }
  check_refused "--port '70000' is not a port number 1..65535" --port 70000
  check_refused "--port 'http' is not a port number 1..65535" --port http
  check_refused "--listen 'localhost' is not an IP address" --listen localhost
  check_refused "--client-queue '1' is not a size in kB 64..1048576" --client-queue 1
  check_refused "--topic nonsense is not a topic of the contract" --topic nonsense
  check_refused "--allow-origin 'viz.example.com' is not an origin scheme://host[:port]" --allow-origin viz.example.com
  check_refused "--allow-origin 'https://viz.example.com/' is not an origin" --allow-origin https://viz.example.com/
  check_refused "--tls-cert and --tls-key go together" --tls-cert "$work/none.pem"
  # TLS files: missing, not PEM, a key that is not the certificate's; refused before listening.
  check_refused "--tls-cert $work/none.pem cannot be read: No such file or directory" \
    --tls-cert "$work/none.pem" --tls-key "$work/none.pem"
  if command -v openssl >/dev/null; then
    openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=127.0.0.1 -keyout "$work/key.pem" -out "$work/cert.pem" 2>/dev/null
    openssl genpkey -algorithm RSA -pkeyopt rsa_keygen_bits:2048 -out "$work/other.pem" 2>/dev/null
    echo "not a certificate" >"$work/junk.pem"
    check_refused "--tls-cert $work/junk.pem: not a PEM certificate (chain): " --tls-cert "$work/junk.pem" --tls-key "$work/key.pem"
    check_refused "--tls-key $work/cert.pem: not a PEM private key: " --tls-cert "$work/cert.pem" --tls-key "$work/cert.pem"
    check_refused "--tls-key $work/other.pem is not the private key of the certificate in --tls-cert $work/cert.pem" \
      --tls-cert "$work/cert.pem" --tls-key "$work/other.pem"
    check_refused "--tls-key $work cannot be read: " --tls-cert "$work/cert.pem" --tls-key "$work"
  else
    fail "openssl is not installed (scripts/setup.sh test)"
  fi
  timeout 20 "$ctl" --domain "$domain" --bus sim0 serve 2>"$work/err"; status=$?
  [ $status -eq 2 ] && grep -q "bus and --address do not apply" "$work/err" || fail "--bus: $status $(cat "$work/err")"
  ;;
*)
  echo "usage: serve_test.sh PMU-SERVICE PMUCTL SOURCE-DIR foxglove|slow|tls|cli" >&2; exit 2 ;;
esac
if [ $failures -ne 0 ]; then
  echo "--- serve stderr" >&2; tail -n 30 "$work/serve.err" >&2 2>/dev/null
  echo "--- service log" >&2; tail -n 20 "$work/service.log" >&2 2>/dev/null
  exit 1
fi
echo "serve $mode: PASS"
