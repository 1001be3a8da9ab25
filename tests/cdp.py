"""Drive headless Chromium over the DevTools protocol (a websocket), for tests of pages
that run script and submit forms (tests/test_serve_browser.py).

Chromium from Debian (``chromium-headless-shell``, found like tests/browser.py finds it)
is started with ``--remote-debugging-port=0`` on a fresh profile, all host lookups
failing (nothing may be fetched from outside; 127.0.0.1 is an address, not a lookup).
One page per :class:`Page`; :meth:`Page.eval` runs an expression and returns its value;
dialogs (``alert``) are recorded in :attr:`Browser.dialogs` and dismissed, console
messages in :attr:`Browser.console`.
"""

from __future__ import annotations

import base64
import json
import os
import re
import signal
import subprocess
import tempfile
import time

import pytest
from browser import FLAGS as _FLAGS

# every host lookup fails, as for the reports; the server under test is 127.0.0.1
FLAGS = tuple(
    "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1" if f.startswith("--host-resolver-rules") else f
    for f in _FLAGS
)


class Browser:
    def __init__(self, chromium: str, downloads: str | None = None):
        websocket = pytest.importorskip("websocket")
        self._profile = tempfile.TemporaryDirectory(prefix="armdyn-cdp-")
        self.proc = subprocess.Popen(
            [
                chromium,
                *FLAGS,
                f"--user-data-dir={self._profile.name}",
                "--remote-debugging-port=0",
                "--window-size=1280,900",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )  # Debian's binary is a wrapper script: kill the group
        url, deadline, seen = None, time.monotonic() + 60, []
        while time.monotonic() < deadline and url is None:
            line = self.proc.stderr.readline()
            if not line and self.proc.poll() is not None:
                break
            seen.append(line)
            m = re.search(r"DevTools listening on (ws://\S+)", line)
            url = m.group(1) if m else None
        if url is None:
            self.close()
            raise AssertionError("Chromium gave no DevTools address:\n" + "".join(seen[-20:]))
        self.ws = websocket.create_connection(url, timeout=60, suppress_origin=True)
        self._id = 0
        self.dialogs: list[str] = []
        self.console: list[str] = []
        self.events: list[dict] = []
        if downloads:
            self.call(
                "Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": downloads, "eventsEnabled": True}
            )

    def call(self, method: str, params: dict | None = None, session: str | None = None, timeout: float = 60):
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            reply = json.loads(self.ws.recv())
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise AssertionError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self._event(reply)
        raise AssertionError(f"{method}: no reply within {timeout} s")

    def _event(self, ev: dict) -> None:
        self.events.append(ev)
        method = ev.get("method")
        if method == "Page.javascriptDialogOpening":
            self.dialogs.append(ev["params"].get("message", ""))
            self.ws.send(
                json.dumps(
                    {
                        "id": 10**9 + len(self.dialogs),
                        "method": "Page.handleJavaScriptDialog",
                        "params": {"accept": False},
                        "sessionId": ev.get("sessionId"),
                    }
                )
            )
        elif method == "Runtime.consoleAPICalled":
            self.console.append(" ".join(str(a.get("value", a.get("description", ""))) for a in ev["params"]["args"]))
        elif method == "Log.entryAdded":
            self.console.append(ev["params"]["entry"].get("text", ""))

    def page(self) -> Page:
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable", session=session)
        return Page(self, session)

    def close(self) -> None:
        try:
            if getattr(self, "ws", None) is not None:
                self.ws.close()
        finally:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)  # the wrapper, the browser and its helpers
            except ProcessLookupError:
                pass
            self.proc.wait()
            self._profile.cleanup()


class Page:
    def __init__(self, browser: Browser, session: str):
        self.b, self.session = browser, session

    def eval(self, expression: str, timeout: float = 60):
        r = self.b.call(
            "Runtime.evaluate",
            {"expression": expression, "returnByValue": True, "awaitPromise": True},
            self.session,
            timeout,
        )
        if "exceptionDetails" in r:
            raise AssertionError(f"page script failed: {r['exceptionDetails'].get('text')}: {expression[:200]}")
        return r["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 60, what: str = "") -> object:
        """Poll ``expression`` until it is truthy; its value."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                value = self.eval(expression)
            except AssertionError:
                value = None  # mid-navigation
            if value:
                return value
            time.sleep(0.2)
        raise AssertionError(f"timed out after {timeout} s waiting for {what or expression}")

    def goto(self, url: str, timeout: float = 60) -> None:
        self.b.call("Page.navigate", {"url": url}, self.session)
        self.wait_for(
            f"document.readyState === 'complete' && location.href.startsWith({json.dumps(url[:40])})",
            timeout,
            f"{url} to load",
        )

    def screenshot(self, path, full: bool = True) -> None:
        params = {"format": "png"}
        if full:
            h = self.eval("Math.ceil(document.documentElement.scrollHeight)")
            params.update(
                captureBeyondViewport=True, clip={"x": 0, "y": 0, "width": 1280, "height": min(h, 4000), "scale": 1}
            )
        data = self.b.call("Page.captureScreenshot", params, self.session)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))
