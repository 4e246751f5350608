"""Every built page rendered with headless Chromium (``python -m navbook screenshots``), with the checks
only a rendered page allows; Chromium is driven over the DevTools protocol on a pipe.

``screenshots HTML_DIR OUT_DIR``
    Render every page with headless Chromium (1400 px wide, full page height), record the page heights and
    list output blocks that overflow the content column.
"""

from __future__ import annotations

import base64
import csv
import fcntl
import html
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .landing import read_chapter_sources

CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
)
CHROMIUM_MISSING = (
    "chromium not found: install it with 'apt-get install -y chromium' (Debian package "
    "chromium) or pass --chromium /path/to/chromium"
)

#: JavaScript run on each page: output blocks and tables wider than the article (cut or scrolling).
_OVERFLOW_JS = r"""(() => {
  const art = document.querySelector('article') || document.body;
  const right = art.getBoundingClientRect().right;
  const out = [];
  const heading = el => { let h = null;
    document.querySelectorAll('h1, h2, h3').forEach(x => {
      if (x.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING) h = x; });
    return h ? h.textContent.replace(/[#\s]+$/, '').trim() : ''; };
  art.querySelectorAll('.cell_output pre, .cell_output .output, .cell_output img, table').forEach(el => {
    const r = el.getBoundingClientRect();
    const over = Math.max(el.scrollWidth - el.clientWidth, r.right - right);
    if (r.width > 0 && over > 2) out.push({heading: heading(el), overflow_px: Math.round(over),
      what: el.tagName.toLowerCase() + '.' + (el.className || '').toString().split(' ').slice(0, 2).join('.'),
      text: (el.innerText || '').trim().slice(0, 60)});
  });
  return out; })()"""


# Every figure in the article: its natural width (the PNG's pixels) and the width the page shows it at.
_FIGURES_JS = r"""(() => {
  const art = document.querySelector('article') || document.body;
  const heading = el => { let h = null;
    document.querySelectorAll('h1, h2, h3').forEach(x => {
      if (x.compareDocumentPosition(el) & Node.DOCUMENT_POSITION_FOLLOWING) h = x; });
    return h ? h.textContent.replace(/[#\s]+$/, '').trim() : ''; };
  return [...art.querySelectorAll('img')].map(el => ({heading: heading(el),
    src: (el.getAttribute('src') || '').split('/').pop(), natural_px: el.naturalWidth,
    shown_px: Math.round(el.getBoundingClientRect().width)}));
})()"""


#: The first screen of a page (1400 x 900 px): each source's headline verdict must end within it.
FIRST_SCREEN_PX = 900
#: The tallest a chapter may be at 1400 px with its folds closed: 15 screens.
CHAPTER_MAX_PX = 15 * FIRST_SCREEN_PX
#: Opens every fold of a page (``<details>``: a section's evidence, captioned tables, code).
_OPEN_FOLDS_JS = "document.querySelectorAll('details').forEach(d => { d.open = true; }); "
#: Every headline verdict on a page (``.navbook-headline``): where it ends, from the top of the page.
_HEADLINES_JS = r"""(() => [...document.querySelectorAll('.navbook-headline')].map(el => ({
  bottom_px: Math.round(el.getBoundingClientRect().bottom + window.scrollY),
  text: (el.innerText || '').trim().slice(0, 80)})))()"""


#: A figure displayed below this share of its natural width is flagged (:func:`shrunk_figures`).
MIN_DISPLAY_SHARE = 0.75


def shrunk_figures(figures, min_share: float | None = None) -> list[dict]:
    """The figures displayed below ``min_share`` (default
    :data:`MIN_DISPLAY_SHARE`, 75 %) of their natural width, each
    ``{"heading", "src", "natural_px", "shown_px", "share"}``, from records of the page's images
    (``natural_px``: the image's own width; ``shown_px``: its width on the page).  Images not loaded or
    not shown (a width of 0) are not figures on the page and are skipped."""

    limit = MIN_DISPLAY_SHARE if min_share is None else float(min_share)
    if not 0 < limit <= 1:
        raise ValueError(f"min_share={min_share!r}: must be in (0, 1]")
    out = []
    for f in figures:
        natural, shown = float(f.get("natural_px") or 0), float(f.get("shown_px") or 0)
        if natural <= 0 or shown <= 0:
            continue
        share = shown / natural
        if share < limit:
            out.append(
                {
                    "heading": f.get("heading", ""),
                    "src": f.get("src", ""),
                    "natural_px": int(natural),
                    "shown_px": int(shown),
                    "share": round(share, 3),
                }
            )
    return out


class _Chrome:
    """Headless Chromium driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``: the
    browser reads JSON messages from fd 3 and writes to fd 4, each ending with a NUL byte)."""

    def __init__(self, binary: str, timeout_s: float = 60.0):
        self.timeout_s = timeout_s
        self.profile = tempfile.mkdtemp(prefix="navbook-chromium-")
        to_chrome_r, self._to_chrome_w = os.pipe()
        self._from_chrome_r, from_chrome_w = os.pipe()

        def child_fds():  # runs in the child before exec: put the pipe ends on fds 3 and 4
            a = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [
                binary,
                *CHROMIUM_FLAGS,
                f"--user-data-dir={self.profile}",
                "--remote-debugging-pipe",
                "--hide-scrollbars",
                "about:blank",
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=child_fds,
            close_fds=False,
        )
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict] = []

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._to_chrome_w, json.dumps(msg).encode() + b"\0")
        while True:
            m = self._read()
            if m.get("id") == self._id:
                if "error" in m:
                    raise RuntimeError(f"chromium: {method}: {m['error'].get('message')}")
                return m.get("result", {})
            self.events.append(m)

    def wait_event(self, method: str, session: str | None = None) -> dict:
        while True:
            for k, e in enumerate(self.events):
                if e.get("method") == method and (session is None or e.get("sessionId") == session):
                    return self.events.pop(k)
            self.events.append(self._read())

    def wait_loaded(self, session: str, url: str) -> None:
        """Poll until the page at ``url`` has finished loading (events of the blank page that preceded it
        must not be mistaken for its load event)."""
        deadline = time.monotonic() + self.timeout_s
        probe = {"expression": "document.readyState + ' ' + location.href", "returnByValue": True}
        while time.monotonic() < deadline:
            try:
                state = self.send("Runtime.evaluate", probe, session=session)["result"].get(
                    "value", ""
                )
            except RuntimeError:  # the context was replaced by the navigation: ask again
                state = ""
            if state == f"complete {url}":
                self.events.clear()
                return
            time.sleep(0.1)
        raise TimeoutError(f"chromium: {url} did not load within {self.timeout_s:.0f} s")

    def _read(self) -> dict:
        deadline = time.monotonic() + self.timeout_s
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([self._from_chrome_r], [], [], max(left, 0))
            if not ready:
                raise TimeoutError(f"chromium did not answer within {self.timeout_s:.0f} s")
            chunk = os.read(self._from_chrome_r, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium exited")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def close(self):
        try:
            self.send("Browser.close")
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_chrome_w, self._from_chrome_r):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)


def find_chromium(explicit: str | None = None) -> str | None:
    """The Chromium binary: ``explicit``, else ``chromium`` / ``chromium-browser`` / ``google-chrome``."""
    if explicit:
        return explicit if Path(explicit).exists() or shutil.which(explicit) else None
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    return None


#: The tallest single screenshot (px): Chromium draws taller full-page captures shifted and with blank
#: blocks (seen on the 25,000 px gyro page), so a taller page is written as viewport-high tiles.
TILE_PX = 16000


def _capture(chrome, session, metrics: dict, height: int, png: Path) -> None:
    """Capture the page in ``session`` at its full ``height`` into ``png``; a page taller than
    :data:`TILE_PX` as viewport-high tiles ``png``, ``<stem>-2.png``, ... (Chromium refuses one capture taller
    than its texture limit, "Page is too large")."""
    if height <= TILE_PX:
        chrome.send(
            "Emulation.setDeviceMetricsOverride", {**metrics, "height": height}, session=session
        )
        # let the theme's sidebar transitions (0.25 s) finish at the new size before the capture
        chrome.send(
            "Runtime.evaluate",
            {
                "expression": "window.scrollTo(0, 0); new Promise(r => "
                "setTimeout(r, 400)).then(() => 1)",
                "awaitPromise": True,
            },
            session=session,
        )
        # the viewport is the whole page: no captureBeyondViewport, which lays a long chapter out again
        # without its left sidebar and shifted left (seen on every chapter page)
        shot = chrome.send("Page.captureScreenshot", {"format": "png"}, session=session)
        png.write_bytes(base64.b64decode(shot["data"]))
        return
    chrome.send(
        "Emulation.setDeviceMetricsOverride", {**metrics, "height": TILE_PX}, session=session
    )
    for k, top in enumerate(range(0, height, TILE_PX)):
        chrome.send(
            "Runtime.evaluate",
            {
                "expression": f"window.scrollTo(0, {top}); new Promise("
                "r => setTimeout(r, 200)).then(() => 1)",
                "awaitPromise": True,
            },
            session=session,
        )
        shot = chrome.send("Page.captureScreenshot", {"format": "png"}, session=session)
        tile = png if k == 0 else png.with_name(f"{png.stem}-{k + 1}.png")
        tile.write_bytes(base64.b64decode(shot["data"]))


def screenshots(
    html_dir: Path,
    out_dir: Path,
    width: int = 1400,
    chromium: str | None = None,
    settle_s: float = 0.5,
) -> int:
    """Render every page under ``html_dir`` at ``width`` px, full page height, into ``out_dir`` (same
    relative names, ``.png``, folds closed as a reader first sees the page, and ``-open.png`` with every fold
    open; a page taller than :data:`TILE_PX` as tiles ``-2.png``, ``-3.png``, ...); write ``heights.csv``
    (page, height with folds closed and open) and ``long.json`` (chapters taller than
    :data:`CHAPTER_MAX_PX` with their folds closed) and ``overflow.json`` (output blocks
    or tables wider than the content column, by page) and ``shrunk.json`` (figures displayed below 75 % of
    their natural width, :func:`shrunk_figures`, by page) and ``headlines.json`` (headline verdicts,
    ``.navbook-headline``, that end below the first :data:`FIRST_SCREEN_PX` px).  Returns 2 if Chromium
    is missing, 1 if a chapter is too tall, a figure is shown shrunk or a headline verdict is not on the
    first screen (the figures and overflow are checked with every fold open; every
    page is still rendered and listed), else 0."""
    binary = find_chromium(chromium)
    if binary is None:
        print(CHROMIUM_MISSING, file=sys.stderr)
        return 2
    html_dir, out_dir = Path(html_dir).resolve(), Path(out_dir)
    pages = [
        p
        for p in sorted(html_dir.rglob("*.html"))
        if p.relative_to(html_dir).parts[0] not in ("_modules", "_sources", "_static", "_images")
        and p.name not in ("search.html", "genindex.html", "py-modindex.html")
        and 'http-equiv="refresh"'
        not in p.read_text(encoding="utf-8", errors="replace")[:2000].lower()
    ]
    out_dir.mkdir(parents=True, exist_ok=True)
    chrome = _Chrome(binary)
    heights, overflow, shrunk, headlines, long_pages = [], {}, {}, {}, {}
    toc = html_dir.parent.parent / "_toc.yml"
    chapters = set(read_chapter_sources(toc.with_name("chapters.csv"))) if toc.exists() else set()
    try:
        for page in pages:
            rel = page.relative_to(html_dir)
            target = chrome.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            session = chrome.send("Target.attachToTarget", {"targetId": target, "flatten": True})[
                "sessionId"
            ]
            chrome.send("Page.enable", session=session)
            metrics = {"width": width, "height": 900, "deviceScaleFactor": 1, "mobile": False}
            chrome.send("Emulation.setDeviceMetricsOverride", metrics, session=session)
            chrome.send("Page.navigate", {"url": page.as_uri()}, session=session)
            chrome.wait_loaded(session, page.as_uri())
            wait = (
                f"new Promise(r => setTimeout(r, {int(settle_s * 1000)}))"
                ".then(() => (window.MathJax && MathJax.startup) ? MathJax.startup.promise : null)"
                ".then(() => document.fonts.ready).then(() => 1)"
            )
            chrome.send(
                "Runtime.evaluate", {"expression": wait, "awaitPromise": True}, session=session
            )
            js_height = (
                "Math.max(document.documentElement.scrollHeight, document.body.scrollHeight, "
                "...[...document.querySelectorAll('.bd-main, .bd-container, .bd-page-width')]"
                ".map(e => e.scrollHeight))"
            )
            closed_h = int(
                chrome.send(
                    "Runtime.evaluate",
                    {"expression": js_height, "returnByValue": True},
                    session=session,
                )["result"]["value"]
            )
            if rel.parts[0] == "_generated" and rel.stem in chapters and closed_h > CHAPTER_MAX_PX:
                long_pages[str(rel)] = closed_h
            heads = (
                chrome.send(
                    "Runtime.evaluate",
                    {"expression": _HEADLINES_JS, "returnByValue": True},
                    session=session,
                )["result"].get("value")
                or []
            )
            late = [hd for hd in heads if hd["bottom_px"] > FIRST_SCREEN_PX]
            if late:
                headlines[str(rel)] = late
            png = out_dir / rel.with_suffix(".png")
            png.parent.mkdir(parents=True, exist_ok=True)
            # the page as a reader first sees it (folds closed), then with every fold open: the figures and
            # tables inside the folds are checked and captured too (page-open.png)
            _capture(chrome, session, metrics, closed_h, png)
            folds = chrome.send(
                "Runtime.evaluate",
                {
                    "expression": "document.querySelectorAll('details').length",
                    "returnByValue": True,
                },
                session=session,
            )["result"]["value"]
            h = closed_h
            if folds:
                h = int(
                    chrome.send(
                        "Runtime.evaluate",
                        {"expression": _OPEN_FOLDS_JS + js_height, "returnByValue": True},
                        session=session,
                    )["result"]["value"]
                )
                _capture(chrome, session, metrics, h, png.with_name(png.stem + "-open.png"))
            chrome.send(
                "Emulation.setDeviceMetricsOverride",
                {**metrics, "height": min(h, TILE_PX)},
                session=session,
            )
            found = (
                chrome.send(
                    "Runtime.evaluate",
                    {"expression": _OVERFLOW_JS, "returnByValue": True},
                    session=session,
                )["result"].get("value")
                or []
            )
            small = shrunk_figures(
                chrome.send(
                    "Runtime.evaluate",
                    {"expression": _FIGURES_JS, "returnByValue": True},
                    session=session,
                )["result"].get("value")
                or []
            )
            chrome.send("Target.closeTarget", {"targetId": target})
            heights.append((str(rel), closed_h, h))
            if found:
                overflow[str(rel)] = found
            if small:
                shrunk[str(rel)] = small
            note = f"; {len(found)} block(s) wider than the content column" if found else ""
            note += f"; {len(small)} figure(s) shown below 75 % of their width" if small else ""
            print(f"{rel}: {width} x {h} px -> {png}{note}", flush=True)
    finally:
        chrome.close()
    with open(out_dir / "heights.csv", "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["page", "height_px", "height_open_px"])
        w.writerows(heights)
    for name, found in (
        ("overflow.json", overflow),
        ("shrunk.json", shrunk),
        ("headlines.json", headlines),
    ):
        (out_dir / name).write_text(
            json.dumps(found, indent=1, ensure_ascii=False) + "\n", encoding="utf-8"
        )
    for page, items in overflow.items():
        for it in items:
            print(
                f"  wider than the column: {page}: {it['what']} by {it['overflow_px']} px under "
                f"'{it['heading']}': {html.unescape(it['text'])[:50]!r}",
                file=sys.stderr,
            )
    for page, items in shrunk.items():
        print(f"  figures shrunk on {page}: {len(items)}", file=sys.stderr)
        for it in items:
            print(
                f"    {it['src']} shown at {it['shown_px']} of {it['natural_px']} px "
                f"({100 * it['share']:.0f} %) under '{it['heading']}'",
                file=sys.stderr,
            )
    for page, items in headlines.items():
        for it in items:
            print(
                f"  headline verdict below the first screen ({FIRST_SCREEN_PX} px) on {page}: ends at "
                f"{it['bottom_px']} px: {it['text'][:60]!r}",
                file=sys.stderr,
            )
    print(
        f"screenshots: {len(heights)} pages -> {out_dir} (heights.csv, long.json, overflow.json, shrunk.json, "
        f"headlines.json)"
    )
    for page, h in long_pages.items():
        print(
            f"  chapter taller than {CHAPTER_MAX_PX // FIRST_SCREEN_PX} screens with its folds closed: {page}: "
            f"{h} px (limit {CHAPTER_MAX_PX} px): put a section's evidence behind its fold ({{evidence}})",
            file=sys.stderr,
        )
    (out_dir / "long.json").write_text(json.dumps(long_pages, indent=1) + "\n", encoding="utf-8")
    if long_pages:
        return 1
    if headlines:
        print(
            f"screenshots: {sum(map(len, headlines.values()))} headline verdict(s) on {len(headlines)} "
            f"page(s) are not on the first {FIRST_SCREEN_PX} px: shorten what comes before them",
            file=sys.stderr,
        )
        return 1
    if shrunk:
        print(
            f"screenshots: {sum(map(len, shrunk.values()))} figure(s) on {len(shrunk)} page(s) shown below "
            f"75 % of their natural width (draw them at most 7.5 in wide: navbook.report.use_style, "
            f"report.panels)",
            file=sys.stderr,
        )
        return 1
    return 0
