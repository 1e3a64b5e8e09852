"""Drive `rest-embree view` in headless Chromium through the DevTools protocol, as a person
would: open the page, wait for the final frame, move the lattice's beta slider to 0.9, wait for
the new final frame, click a pixel of the lattice, and check what the page shows against what
the server says of that pixel and the light-cone algebra (emitted at t = view time - lookback,
approaching points blueshifted). A screenshot of the page is kept.

    python3 browser-test.py REST_EMBREE CHROMIUM SCREENSHOT.png
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

import websocket  # websocket-client

exe, chromium, shot = sys.argv[1], sys.argv[2], sys.argv[3]
root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
work = tempfile.mkdtemp(prefix="rest-embree-browser-")
procs = []


def fail(why):
    print(f"browser-test: FAILED: {why}", file=sys.stderr)
    sys.exit(1)


try:
    viewer = subprocess.Popen(
        [exe, "view", "scenes/lattice.toml", "--no-browser", "--out", work],
        cwd=root, stdout=subprocess.PIPE, text=True)
    procs.append(viewer)
    url = None
    for _ in range(3):
        line = viewer.stdout.readline()
        if "http://" in line:
            url = line.strip()
            break
    if not url:
        fail("the viewer printed no URL")
    token = url.split("token=")[1]
    base = url.split("/?")[0]

    profile = os.path.join(work, "profile")
    chrome = subprocess.Popen(
        [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--remote-debugging-port=0", f"--user-data-dir={profile}", "--window-size=1300,900",
         "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    procs.append(chrome)
    port_file = os.path.join(profile, "DevToolsActivePort")
    for _ in range(300):
        if os.path.exists(port_file) and open(port_file).read().count("\n") >= 1:
            break
        time.sleep(0.1)
    else:
        fail("Chromium did not start its DevTools server")
    port = open(port_file).read().split("\n")[0]
    targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list"))
    page = next(t for t in targets if t["type"] == "page")
    ws = websocket.create_connection(page["webSocketDebuggerUrl"], timeout=60)
    ids = iter(range(1, 10**9))

    def call(method, **params):
        i = next(ids)
        ws.send(json.dumps({"id": i, "method": method, "params": params}))
        while True:
            m = json.loads(ws.recv())
            if m.get("id") == i:
                if "error" in m:
                    fail(f"{method}: {m['error']}")
                return m.get("result", {})

    def js(expr):
        r = call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            fail(f"{expr}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait(expr, what, seconds=60):
        t0 = time.time()
        while time.time() - t0 < seconds:
            if js(expr):
                return time.time() - t0
            time.sleep(0.05)
        status = js("document.getElementById('status').textContent")
        error = js("document.getElementById('error').textContent")
        fail(f"waited {seconds} s for {what}; status: {status}, error: {error}")

    call("Page.enable")
    call("Runtime.enable")
    call("Page.navigate", url=url)
    wait("document.body && document.body.dataset.final === 'true'", "the first final frame")
    print("browser-test: the page drew the scene:", js("document.getElementById('status').textContent"))

    # A group at rest starts moving along +x, away from this camera: type -1 into the first
    # direction box, as a user does, so that the lattice approaches.
    js("""(() => { const n = document.querySelector('input.beta[data-group="lattice"]')
            .closest('div').querySelector('label.dir input');
            n.value = '-1'; n.dispatchEvent(new Event('change', { bubbles: true })); })()""")
    # Move the slider as a hand does: a run of input events to 0.9.
    before = int(js("document.body.dataset.version"))
    for b in ["0.3", "0.6", "0.8", "0.9"]:
        js(f"""(() => {{ const r = document.querySelector('input.beta[data-group="lattice"]');
                r.value = '{b}'; r.dispatchEvent(new Event('input', {{ bubbles: true }})); }})()""")
        time.sleep(0.02)
    took = wait(f"+document.body.dataset.version > {before} && document.body.dataset.level === '0'",
                "the first frame after the change")
    print(f"browser-test: first frame after the change shown within {1000 * took:.0f} ms (polled)")
    wait(f"+document.body.dataset.version >= {before + 1} && document.body.dataset.final === 'true'",
         "the final frame at beta 0.9")
    sent = js("JSON.stringify(viewer.state.groups.lattice)")
    state = json.loads(sent)
    if abs(state["beta"] - 0.9) > 1e-12 or state["direction"] != [-1, 0, 0]:
        fail(f"the slider and direction box set {sent}")

    # Click pixels of the image until one shows the lattice.
    rect = js("(() => { const r = document.getElementById('frame').getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()")
    probe = None
    for fx, fy in [(0.5, 0.5), (0.53, 0.5), (0.47, 0.47), (0.6, 0.55), (0.4, 0.4), (0.7, 0.3)]:
        x, y = rect[0] + fx * rect[2], rect[1] + fy * rect[3]
        js("delete document.body.dataset.probe")
        for kind in ["mouseMoved", "mousePressed", "mouseReleased"]:
            call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)
        wait("document.body.dataset.probe !== undefined", "the click's answer", 20)
        probe = json.loads(js("document.body.dataset.probe"))
        if probe["hit"]:
            break
    if not probe or not probe["hit"]:
        fail("no click found the lattice")
    shown = js("Object.fromEntries([...document.querySelectorAll('#probe tr')].map(r => [r.cells[0].textContent, r.cells[1].textContent]))")
    # The server's own answer for that pixel of the page's client.
    px, py = probe["pixel"]
    client = js("viewer.client")
    q = f"{base}/api/probe?token={token}&client={client}&x={px}&y={py}"
    server = json.load(urllib.request.urlopen(q))
    if server != probe:
        fail(f"the page shows {probe}, the server says {server}")
    if not shown["object"].startswith("lattice") or shown["group"] != "lattice":
        fail(f"shown: {shown}")
    if abs(float(shown["lookback"]) - probe["lookback"]) > 1e-4 * max(1.0, probe["lookback"]):
        fail(f"lookback shown {shown['lookback']} against {probe['lookback']}")
    t_emit = float(shown["emitted at t"])
    if abs(t_emit - (3.0 - probe["lookback"])) > 1e-3:
        fail(f"emitted at {t_emit}, view time 3, lookback {probe['lookback']}")
    if not probe["doppler"] > 1.0:
        fail(f"the lattice approaches at 0.9c: its Doppler factor {probe['doppler']} should exceed 1")
    print(f"browser-test: clicked pixel {px},{py}: {shown}")

    png = call("Page.captureScreenshot", format="png")["data"]
    import base64
    os.makedirs(os.path.dirname(os.path.abspath(shot)), exist_ok=True)
    with open(shot, "wb") as f:
        f.write(base64.b64decode(png))
    print(f"browser-test: passed; screenshot {shot}")
finally:
    for p in procs:
        p.terminate()
    for p in procs:
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            p.kill()
    shutil.rmtree(work, ignore_errors=True)
