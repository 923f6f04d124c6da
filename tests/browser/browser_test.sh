#!/usr/bin/env bash
# pmuctl serve (docs/interface.md section 9.2) read as an integrator's Foxglove web app reads
# it: a page in headless Chromium, served from a local web server, connects with the browser's
# own WebSocket, decodes pmu/voltages and pmu/battery with Foxglove's omgidl decoder and plots
# a voltage against the player's time axis (page.mjs; judged by drive.mjs). The server runs
# against pmu-service on the simulated power system.
#   browser_test.sh PMU-SERVICE PMUCTL SOURCE-DIR SCREENSHOT.png MODE
# MODE: http-websocket  http page on 127.0.0.1, ws://, subprotocol foxglove.websocket.v1
#       http-sdk        http page on 127.0.0.1, ws://, subprotocol foxglove.sdk.v1
#       https-sdk       https page of a site of its own (https://viz.test:PORT, a certificate
#                       made here), wss:// (serve --tls-cert/--tls-key --allow-origin that site),
#                       foxglove.sdk.v1
# In every mode a page of another site (other.test, an origin serve does not allow) is then
# refused. *.test names this host for Chromium (drive.mjs).
# Skipped (exit 77) with the reason when Chromium, Node.js or tests/browser's npm packages
# (scripts/setup.sh: npm ci there) are missing.
set -uo pipefail
svc=$1 ctl=$2 src=$3 screenshot=$4 mode=$5
here="$(cd "$(dirname "$0")" && pwd)"
chromium=${PMU_CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || { echo "SKIP: $chromium is not installed (scripts/setup.sh installs Debian's chromium)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node is not installed (scripts/setup.sh installs it)"; exit 77; }
for p in puppeteer-core esbuild @foxglove/omgidl-parser @foxglove/omgidl-serialization; do
  [ -d "$here/node_modules/$p" ] || { echo "SKIP: $p is not installed in tests/browser (scripts/setup.sh runs npm ci there)"; exit 77; }
done
case "$mode" in
  http-websocket) scheme=http subprotocol=foxglove.websocket.v1 ;;
  http-sdk) scheme=http subprotocol=foxglove.sdk.v1 ;;
  https-sdk) scheme=https subprotocol=foxglove.sdk.v1 ;;
  *) echo "usage: browser_test.sh PMU-SERVICE PMUCTL SOURCE-DIR SCREENSHOT.png http-websocket|http-sdk|https-sdk" >&2; exit 2 ;;
esac
. "$src/tests/support/dds_domain.sh"
pmu_test_dds_domain || exit 1
domain=$PMU_TEST_DDS_DOMAIN
export PMU_QOS_FILE="$src/deploy/qos.xml"
work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*" >&2
  echo "--- serve stderr" >&2; tail -n 20 "$work/serve.err" >&2
  echo "--- service log" >&2; tail -n 10 "$work/service.log" >&2
  exit 1
}
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
# wait_for FILE PID PATTERN: FILE holds a line matching PATTERN (false once PID exited, or after 20 s)
wait_for() {
  for _ in $(seq 200); do
    grep -q "$3" "$1" 2>/dev/null && return 0
    kill -0 "$2" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}

# The page: page.mjs and the omgidl packages in one script for the browser.
mkdir "$work/site"
cp "$here/index.html" "$work/site/"
"$here/node_modules/.bin/esbuild" "$here/page.mjs" --bundle --format=iife --platform=browser --log-level=warning \
  --outfile="$work/site/page.js" || fail "esbuild could not bundle page.mjs"

tls=()
if [ "$scheme" = https ]; then
  openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj "/CN=viz.test" \
    -addext "subjectAltName=DNS:viz.test,DNS:other.test,IP:127.0.0.1" \
    -keyout "$work/key.pem" -out "$work/cert.pem" 2>"$work/openssl.err" || fail "openssl: $(cat "$work/openssl.err")"
  tls=("$work/cert.pem" "$work/key.pem")
fi
node "$here/static_server.mjs" "$work/site" "${tls[@]}" >"$work/site.out" 2>&1 &
pids+=($!)
wait_for "$work/site.out" $! "^$scheme://" || fail "the web server did not start: $(cat "$work/site.out")"
site_port=$(head -n 1 "$work/site.out" | sed 's/.*://')
page_origin="$scheme://127.0.0.1:$site_port"
[ "$scheme" = https ] && page_origin="https://viz.test:$site_port"

"$svc" --config "$src/deploy/examples/sim-power-system.yaml" --domain "$domain" >"$work/service.log" 2>&1 &
pids+=($!)
port=$(free_port)
serve_args=(--port "$port")
ws_url="ws://127.0.0.1:$port"
if [ "$scheme" = https ]; then
  serve_args+=(--tls-cert "$work/cert.pem" --tls-key "$work/key.pem" --allow-origin "$page_origin")
  ws_url="wss://127.0.0.1:$port"
fi
"$ctl" --domain "$domain" serve "${serve_args[@]}" 2>"$work/serve.err" &
server=$!; pids+=($server)
wait_for "$work/serve.err" "$server" "serving .* on wss\?://" || fail "serve did not start: $(cat "$work/serve.err")"
node "$here/drive.mjs" "$chromium" "$page_origin" "$ws_url" "$subprotocol" 10 "$screenshot" || fail "the page's view of $ws_url from $page_origin"
grep -q "client 127.0.0.1:[0-9]* connected" "$work/serve.err" || fail "no connect line"
other="$scheme://other.test:$site_port"
node "$here/drive.mjs" "$chromium" "$other" "$ws_url" "$subprotocol" 10 "$work/refused.png" --refused || fail "a page from $other"
grep -q "refused 127.0.0.1:[0-9]*: origin $other is not allowed" "$work/serve.err" || fail "no line saying the page from $other was refused"
echo "browser $mode: PASS (plot: $screenshot)"
