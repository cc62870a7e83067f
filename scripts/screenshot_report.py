"""Render an HTML report in headless Chromium and save a PNG screenshot (to check it looks right).

    python scripts/screenshot_report.py part.html part.png [--width 1100] [--height 2400]

Needs Debian's Chromium (``apt-get install -y chromium``; ``/usr/bin/chromium``) or ``CHROMIUM=/path``.  The
flags keep it off the network (the report needs none: no CDN, images inline) and work as root in a container.
Exit code 0 when the PNG was written; 2 when no Chromium is found.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--force-device-scale-factor=1"]


def find_chromium() -> str | None:
    """The Chromium executable: $CHROMIUM, else chromium / chromium-browser / google-chrome on PATH."""
    env = os.environ.get("CHROMIUM")
    if env:
        return env
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        found = shutil.which(name)
        if found:
            return found
    return None


def screenshot(html_path: str, png_path: str, *, width: int = 1100, height: int = 2400,
               timeout: float = 120.0) -> None:
    """Take the screenshot; raise ``RuntimeError`` with Chromium's output if no PNG appears."""
    exe = find_chromium()
    if exe is None:
        raise FileNotFoundError("no Chromium found (apt-get install -y chromium, or set CHROMIUM)")
    url = "file://" + os.path.abspath(html_path)
    with tempfile.TemporaryDirectory() as profile:
        cmd = [exe, *FLAGS, f"--user-data-dir={profile}", f"--window-size={width},{height}",
               f"--screenshot={os.path.abspath(png_path)}", url]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if not os.path.exists(png_path) or os.path.getsize(png_path) == 0:
        raise RuntimeError(f"chromium wrote no screenshot (exit {proc.returncode}): {proc.stderr[-2000:]}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("html")
    ap.add_argument("png")
    ap.add_argument("--width", type=int, default=1100)
    ap.add_argument("--height", type=int, default=2400)
    args = ap.parse_args(argv)
    try:
        screenshot(args.html, args.png, width=args.width, height=args.height)
    except FileNotFoundError as exc:
        print(f"screenshot_report: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
