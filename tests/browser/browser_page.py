"""The Python side of the browser test helper: opens a page of Lacuna's in headless Chromium through
page_check.mjs and returns what the page reported, its console, errors and requests, and the
screenshot as pixels. Every page feature is tested the same way: run, open, read, look."""

import json
import os
import pathlib
import subprocess

from PIL import Image

HERE = pathlib.Path(__file__).resolve().parent
NODE = os.environ.get("LACUNA_NODE", "node")


def open_page(html, screenshot, element=None, clicks=(), timeout_s=120):
    """Opens `html` (a path), waits until the page is ready, clicks `clicks` (CSS selectors) in order,
    screenshots `element` (a CSS selector; None: the window) into `screenshot`. Returns a dict:
    state (window.lacunaPage), console [{type, text}], errors, requests (URLs other than the page),
    timed_out, and image (a PIL image of the screenshot)."""
    command = [NODE, str(HERE / "page_check.mjs"), str(html), "--screenshot", str(screenshot),
               "--timeout-ms", str(int(timeout_s * 1000))]
    if element:
        command += ["--element", element]
    for selector in clicks:
        command += ["--click", selector]
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s + 60)
    if done.returncode != 0:
        raise RuntimeError(f"page_check failed ({done.returncode}): {done.stderr[-4000:]}")
    result = json.loads(done.stdout)
    result["image"] = Image.open(screenshot).convert("RGB")
    return result


def console_errors(result):
    """Console messages of type error or warning, and uncaught exceptions."""
    return [m["text"] for m in result["console"] if m["type"] in ("error", "warning")] + result["errors"]


def centre_pixels(image, fraction=0.2):
    """The pixels of the centred box `fraction` of the image's width and height."""
    w, h = image.size
    box = (int(w * (0.5 - fraction / 2)), int(h * (0.5 - fraction / 2)),
           int(w * (0.5 + fraction / 2)), int(h * (0.5 + fraction / 2)))
    return list(image.crop(box).getdata())
