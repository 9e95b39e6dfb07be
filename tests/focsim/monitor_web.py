#!/usr/bin/env python3
"""The web view in a real headless browser: focsim --pty <-> foc-monitor
--web <-> Debian's chromium, driven through the DevTools protocol (a small
client over a websocket, standard library only).

    monitor_web.py FOCSIM FOC_MONITOR SRC_DIR WORK_DIR

Registered through tests/common/need.sh: skipped where chromium is missing
(a failure under CI=true).

focsim runs monitor_web.scn (no commands, only its length) paced to wall
time.  The page is loaded; the test clicks Start and Set speed (1000 rpm),
waits until the page shows RUN, fills the scope fields (speed_est and
iq_ref, every period, trigger speed_est rising through 1250 rpm, 25 %
before it), clicks Capture, sets 1500 rpm and clicks Set speed, waits for
the page's capture, lets the speed settle, reads what the page shows and
takes a screenshot (WORK_DIR/monitor-web.png; docs/img/monitor-web.png is
one of these); the motor runs on to the scenario's end.  After focsim has finished, checks against its CSV:
  - the page refreshed its status at least 3 times per second;
  - the state the page shows (RUN) is the CSV's at the end of the run,
    and the estimated speed it shows is the CSV's over the settled last
    second within 1 % (the CSV's speeds vary less than that there);
  - the page's capture equals the CSV sample by sample within 1 LSB (+ the
    CSV's rounding) at the trigger period found on the CSV alone (the
    first crossing of the level after the controller reached RUN), the
    slow step's iq_ref against the previous row;
  - the CSV the page's download link serves holds the same counts;
  - the live plots have been drawn (canvas pixels not all blank).
"""
import base64
import json
import math
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request
from focsim_csv import decimals, read_csv

failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg, flush=True)
    if not cond:
        failures.append(msg)
    return cond


# ------------------------------------------------------ DevTools client --

class Cdp:
    """Chrome DevTools protocol over one websocket (RFC 6455, client side:
    masked text frames out, unmasked frames in)."""

    def __init__(self, ws_url):
        assert ws_url.startswith("ws://")
        hostport, path = ws_url[5:].split("/", 1)
        host, port = hostport.split(":")
        self.sock = socket.create_connection((host, int(port)), timeout=30)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall(("GET /%s HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\n"
                           "Connection: Upgrade\r\nSec-WebSocket-Key: %s\r\n"
                           "Sec-WebSocket-Version: 13\r\n\r\n" % (path, hostport, key)).encode())
        resp = b""
        while b"\r\n\r\n" not in resp:
            resp += self.sock.recv(1)
        if b" 101 " not in resp.split(b"\r\n")[0]:
            raise RuntimeError("websocket handshake: %r" % resp[:80])
        self.next_id = 1

    def _recv_exact(self, n):
        b = b""
        while len(b) < n:
            chunk = self.sock.recv(n - len(b))
            if not chunk:
                raise RuntimeError("websocket closed")
            b += chunk
        return b

    def _send(self, text):
        data = text.encode()
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x81])
        if n < 126:
            head += bytes([0x80 | n])
        elif n < 65536:
            head += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            head += bytes([0x80 | 127]) + struct.pack(">Q", n)
        self.sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def _recv(self):
        msg = b""
        while True:
            b0, b1 = self._recv_exact(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._recv_exact(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._recv_exact(8))[0]
            payload = self._recv_exact(n)
            op = b0 & 0x0F
            if op == 0x9:  # ping: answer it
                continue
            msg += payload
            if b0 & 0x80:
                return msg.decode()

    def call(self, method, **params):
        i = self.next_id
        self.next_id += 1
        self._send(json.dumps({"id": i, "method": method, "params": params}))
        while True:
            m = json.loads(self._recv())
            if m.get("id") == i:
                if "error" in m:
                    raise RuntimeError("%s: %s" % (method, m["error"]))
                return m["result"]

    def js(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError("page script: %s" % r["exceptionDetails"])
        return r["result"].get("value")


# ------------------------------------------------------------- helpers --

def wait_line(path, prefix, proc, timeout=15):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if os.path.exists(path):
            with open(path, errors="replace") as f:
                for line in f:
                    if prefix in line:
                        return line[line.index(prefix) + len(prefix):].strip()
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    raise SystemExit("no '%s' from %s" % (prefix, proc.args[0]))


def wait_page_target(port, browser, timeout=30):
    """The browser's page target: DevTools may list it a moment after its
    'listening' line (a busy machine: a list without it)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and browser.poll() is None:
        targets = json.load(urllib.request.urlopen("http://%s/json/list" % port))
        page = next((t for t in targets if t.get("type") == "page"), None)
        if page is not None:
            return page
        time.sleep(0.1)
    raise SystemExit("chromium listed no page target")


def wait_page(cdp, expr, timeout, what):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            v = cdp.js(expr)
        except RuntimeError:  # the page is still loading
            v = None
        if v:
            return v
        time.sleep(0.05)
    try:
        seen = cdp.js("['state', 'fault', 'log'].map(id => id + ': ' + "
                      "(document.getElementById(id) || {}).textContent).join(' | ')")
    except RuntimeError:
        seen = "(the page did not answer)"
    raise SystemExit("the page never showed %s within %g s; it shows %s" % (what, timeout, seen))



def main():
    focsim, fm, src, work = sys.argv[1:5]
    # tests/common/need.sh skips the test (or fails it under CI=true)
    # where chromium is missing
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    os.makedirs(work, exist_ok=True)
    csv = os.path.join(work, "focsim.csv")
    shot = os.path.join(work, "monitor-web.png")
    for f in (csv, shot):
        if os.path.exists(f):
            os.remove(f)
    procs = []
    profile = tempfile.mkdtemp(prefix="monitor-web-chromium-")
    try:
        # the browser first (its start-up is the slowest), then focsim (paced
        # to wall time from its start), then the tool's web server
        cerr = os.path.join(work, "chromium.err")
        browser = subprocess.Popen([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                                    "--no-first-run", "--disable-extensions",
                                    "--user-data-dir=" + profile, "--remote-debugging-port=0",
                                    "--window-size=1320,1120", "about:blank"],
                                   stdout=subprocess.DEVNULL, stderr=open(cerr, "w"))
        procs.append(browser)
        devtools = wait_line(cerr, "DevTools listening on ", browser, 60)
        port = devtools.split("://", 1)[1].split("/", 1)[0]
        ferr = os.path.join(work, "focsim.err")
        sim = subprocess.Popen([focsim, "--pty", "--scenario", os.path.join(src, "monitor_web.scn"),
                                "--csv", csv], stdout=subprocess.DEVNULL, stderr=open(ferr, "w"))
        procs.append(sim)
        pty = wait_line(ferr, "pty: ", sim)
        wout = os.path.join(work, "web.out")
        webp = subprocess.Popen([sys.executable, fm, "--port", pty, "--web", "--http-port", "0"],
                                stdout=open(wout, "w"), stderr=subprocess.STDOUT)
        procs.append(webp)
        url = wait_line(wout, "web: ", webp)
        page = wait_page_target(port, browser)
        cdp = Cdp(page["webSocketDebuggerUrl"])
        cdp.call("Page.enable")
        cdp.call("Page.navigate", url=url)
        ident = wait_page(cdp, "document.getElementById('ident').textContent", 10, "identify")
        check("focsim" in ident, "page header names the board: %r" % ident)

        u0, t0 = cdp.js("+document.getElementById('updates').textContent"), time.monotonic()
        cdp.js("document.getElementById('btn-start').click()")
        cdp.js("document.getElementById('speed').value = '1000';"
               "document.getElementById('btn-speed').click()")
        wait_page(cdp, "document.getElementById('state').textContent === 'RUN'", 15, "RUN")
        time.sleep(1.0)
        u1, t1 = cdp.js("+document.getElementById('updates').textContent"), time.monotonic()
        rate = (u1 - u0) / (t1 - t0)
        check(rate >= 3.0, "status refreshed %.1f times per second" % rate)

        cdp.js("""(() => { const v = (id, x) => document.getElementById(id).value = x;
                  v('sc-ch', 'speed_est,iq_ref'); v('sc-trig', 'speed_est');
                  v('sc-edge', 'rising'); v('sc-level', '1250'); v('sc-pre', '25');
                  v('sc-decim', '1'); document.getElementById('btn-capture').click(); })()""")
        wait_page(cdp, "document.getElementById('sc-info').textContent === 'armed...'", 10, "armed")
        time.sleep(0.3)  # the tool arms within a few requests
        cdp.js("document.getElementById('speed').value = '1500';"
               "document.getElementById('btn-speed').click()")
        wait_page(cdp, "/frames/.test(document.getElementById('sc-info').textContent)", 10,
                  "the capture")
        cap = cdp.js("window.lastCapture")
        page_csv = cdp.js("fetch('/api/scope.csv').then(r => r.text())")
        time.sleep(1.8)  # settle at 1500 rpm
        shown = cdp.js("""(() => { const g = id => document.getElementById(id).textContent;
                  return { state: g('state'), speed_est: g('speed_est_rpm'),
                           fault: g('fault'), log: g('log') }; })()""")
        blank = cdp.js("""(() => { const c = document.getElementById('plot-speed');
                  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
                  let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; })()""")
        png = cdp.call("Page.captureScreenshot", format="png", captureBeyondViewport=True)["data"]
        with open(shot, "wb") as f:
            f.write(base64.b64decode(png))
        print("page shows: %s" % {k: v for k, v in shown.items() if k != "log"})
        print(shown["log"])
        sim.wait(timeout=60)  # the scenario's end: the CSV is complete
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
        shutil.rmtree(profile, ignore_errors=True)

    check(sim.returncode == 0, "focsim exit status %s" % sim.returncode)
    check(os.path.getsize(shot) > 10000, "screenshot written (%d bytes)" % os.path.getsize(shot))
    check(blank > 1000, "live plot drawn (%d painted pixels)" % blank)
    cols = read_csv(csv)
    t = [float(x) for x in cols["t_s"]]

    # what the page showed against the CSV at the settled end
    t_read = t[-1]
    last = [i for i, ti in enumerate(t) if ti > t_read - 1.0 and cols["state"][i] == "RUN"]
    check(shown["state"] == "RUN" and shown["fault"] == "NONE",
          "page: RUN, no fault (CSV at the end: %s)" % cols["state"][-1])
    if last:
        mean = sum(float(cols["speed_est_rpm"][i]) for i in last) / len(last)
        spread = max(abs(float(cols["speed_est_rpm"][i]) - mean) for i in last)
        page_speed = float(shown["speed_est"].split()[0])
        check(abs(page_speed - mean) <= 0.01 * mean,
              "page speed_est %.1f rpm, CSV's settled mean %.1f rpm (spread %.1f)"
              % (page_speed, mean, spread))

    # the page's capture against the CSV
    if not check(cap and cap["channels"] == ["speed_est", "iq_ref"], "the page holds the capture"):
        return 1
    fs = dict(zip(cap["channels"], cap["fs"]))
    level = round(1250 * 32768 / fs["speed_est"])
    counts = [round(float(v) * 32768 / fs["speed_est"]) for v in cols["speed_est_rpm"]]
    run0 = cols["state"].index("RUN")
    p = next(i for i in range(run0 + 1, len(counts)) if counts[i - 1] < level <= counts[i])
    print("trigger period from the CSV: %d (t = %s s)" % (p, cols["t_s"][p]))
    bad, worst = 0, {}
    for i, row in enumerate(cap["rows"]):
        period = p + i - cap["pre"]
        for c, (name, col, off) in enumerate((("speed_est", "speed_est_rpm", 0),
                                               ("iq_ref", "iq_ref_a", -1))):
            text = cols[col][period + off]
            lsb = fs[name] / 32768
            diff = row[c] * lsb - float(text)
            worst[name] = max(worst.get(name, 0.0), abs(diff) / lsb)
            if abs(diff) > lsb + 0.5 * 10.0 ** -decimals(text) + 1e-12:
                bad += 1
    check(bad == 0, "page capture: %d frames x 2 channels equal to the CSV within 1 LSB "
          "(largest %s LSB), %d mismatches"
          % (len(cap["rows"]), {k: round(v, 3) for k, v in worst.items()}, bad))
    lines = page_csv.strip().splitlines()
    dl = [[int(x) for x in l.split(",")[2::2]] for l in lines[1:]]
    check(lines[0].startswith("k,t_s,speed_est_counts") and dl == cap["rows"],
          "the download link serves the capture (%d rows)" % len(dl))
    print("%d check(s) failed" % len(failures) if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
