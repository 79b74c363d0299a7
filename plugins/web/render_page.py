#!/usr/bin/env python3
"""Render an `atlas view` page in headless Chromium and save its canvas as PNG.

    python3 plugins/web/render_page.py DIR/index.html OUT.png [QUERY] [--timeout S]

QUERY is the page's URL parameters (plugins/web/src/main.js), for example
"still=1&frames=3&size=320x180&output=alpha". Chromium draws WebGL2 in software
(SwiftShader), so no GPU is needed. It is driven over the DevTools protocol on a
pipe (--remote-debugging-pipe: JSON messages ending in NUL on file descriptors 3
and 4), with the standard library only. Exit status 1 with the page's own message
when the page fails or times out.
"""
import argparse
import base64
import fcntl
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time


class Chromium:
    def __init__(self, executable):
        self.profile = tempfile.mkdtemp(prefix="atlas-chromium-")
        to_chrome_r, self.to_chrome = os.pipe()
        self.from_chrome, from_chrome_w = os.pipe()
        # Chromium reads commands on fd 3 and writes replies on fd 4: the child's
        # ends are first moved above 10, so that putting them at 3 and 4 cannot
        # overwrite one with the other.
        child_r = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD, 10)
        child_w = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD, 10)
        for fd in (to_chrome_r, from_chrome_w):
            os.close(fd)

        def place_pipes():
            os.dup2(child_r, 3)
            os.dup2(child_w, 4)

        self.proc = subprocess.Popen(
            [executable, "--headless", "--remote-debugging-pipe", "--no-sandbox", "--no-first-run",
             "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
             f"--user-data-dir={self.profile}", "about:blank"],
            pass_fds=(3, 4), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
            preexec_fn=place_pipes)
        os.close(child_r)
        os.close(child_w)
        self.next_id = 0
        self.buffer = b""

    def send(self, method, params=None, session=None):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.to_chrome, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self.read()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error'].get('message')}")
                return reply.get("result", {})

    def read(self):
        while b"\0" not in self.buffer:
            chunk = os.read(self.from_chrome, 1 << 20)
            if not chunk:
                err = self.proc.stderr.read().decode(errors="replace")[-2000:] if self.proc.stderr else ""
                raise RuntimeError("Chromium closed the DevTools pipe" + (f":\n{err}" if err else ""))
            self.buffer += chunk
        msg, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(msg)

    def close(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def render(page, out, query="", timeout=300, executable=None, log=None):
    """Loads the page, waits for window.atlasViewDone, writes the canvas to `out`.
    Returns the seconds it took; raises RuntimeError with the page's message."""
    executable = executable or os.environ.get("CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    url = pathlib.Path(page).resolve().as_uri() + (f"?{query}" if query else "")
    browser = Chromium(executable)
    t0 = time.monotonic()
    try:
        target = browser.send("Target.createTarget", {"url": url})["targetId"]
        session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        probe = ("JSON.stringify({done: window.atlasViewDone === true, error: window.atlasViewError ?? null,"
                 " status: document.getElementById('status')?.textContent ?? null})")
        last = None
        while True:
            r = browser.send("Runtime.evaluate", {"expression": probe, "returnByValue": True}, session)
            state = json.loads(r.get("result", {}).get("value") or "{}")
            if state.get("error"):
                raise RuntimeError(f"the page failed: {state['error']}")
            if state.get("done"):
                break
            if log and state.get("status") != last:
                last = state.get("status")
                log(f"{time.monotonic() - t0:.0f} s: {last}")
            if time.monotonic() - t0 > timeout:
                raise RuntimeError(f"the page did not finish in {timeout} s (last status: {state.get('status')})")
            time.sleep(0.25)
        r = browser.send("Runtime.evaluate", {"expression": "document.querySelector('canvas').toDataURL('image/png')",
                                              "returnByValue": True}, session)
        data = r["result"]["value"]
        pathlib.Path(out).write_bytes(base64.b64decode(data.split(",", 1)[1]))
        return time.monotonic() - t0
    finally:
        browser.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("page")
    ap.add_argument("out")
    ap.add_argument("query", nargs="?", default="")
    ap.add_argument("--timeout", type=float, default=300)
    a = ap.parse_args()
    try:
        s = render(a.page, a.out, a.query, a.timeout, log=lambda m: print(m, file=sys.stderr))
    except (RuntimeError, OSError) as e:
        print(f"render_page: {e}", file=sys.stderr)
        return 1
    print(f"rendered {a.out} in {s:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
