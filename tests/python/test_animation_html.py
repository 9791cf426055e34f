"""The HTML animation of `imukit animate` is self-contained and its script runs.

No headless browser can be installed from the package registries here, so the page's structure
is validated and, where Node.js is present, its script is run against a minimal DOM and canvas
that record the drawing calls.
"""
import json
import re
import shutil
import subprocess

import pytest

from test_cli_vs_python import ROOT, imukit_bin

STUB = r"""
const fs = require("fs");
const html = fs.readFileSync(process.argv[process.argv.length - 1], "utf8");
const script = html.split("<script>")[1].split("</script>")[0];
const calls = {stroke: 0, fill: 0, arc: 0};
const ctx = new Proxy({}, {get: (o, k) => k in o ? o[k] : (k in calls ? () => calls[k]++ : () => {}),
                           set: (o, k, v) => { o[k] = v; return true; }});
const el = () => ({getContext: () => ctx, width: 560, height: 420, value: 0, max: 0, textContent: "",
                   onclick: null, oninput: null, onmousedown: null});
const els = {view: el(), slider: el(), time: el(), play: el()};
const ticks = [];
const sandbox = {document: {getElementById: id => els[id]}, window: {}, setInterval: (f, ms) => ticks.push([f, ms]), Math, console};
new Function(...Object.keys(sandbox), script)(...Object.values(sandbox));
const first = {...calls};
for (let i = 0; i < 5; i++) ticks[0][0]();
console.log(JSON.stringify({first, after: calls, interval: ticks[0][1], slider_max: els.slider.max,
                            label: els.time.textContent}));
"""


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    d = tmp_path_factory.mktemp("html")
    truth = d / "truth.csv"
    subprocess.run([imukit_bin(), "simulate", str(ROOT / "examples" / "expression.toml"), "--out", str(d / "imu.csv"),
                    "--truth", str(truth)], check=True, capture_output=True)
    out = d / "anim.html"
    subprocess.run([imukit_bin(), "animate", str(truth), "--out", str(out), "--fps", "10"], check=True,
                   capture_output=True)
    return out


def test_page_is_self_contained(page):
    html = page.read_text()
    assert html.startswith("<!DOCTYPE html>")
    assert "<canvas" in html and html.count("<script>") == 1
    assert not re.search(r"https?://|\ssrc=|<link", html), "the page must not load anything"
    frames = json.loads("[" + html.split("const FRAMES = [")[1].split("];")[0] + "]")
    path = json.loads("[" + html.split("const PATH = [")[1].split("];")[0] + "]")
    assert all(len(f) == 9 for f in frames)  # t, travelled path points, position, quaternion
    assert [f[0] for f in frames] == sorted(f[0] for f in frames)
    assert 1 <= frames[0][1] <= frames[-1][1] == len(path) // 3
    for f in frames:
        assert abs(sum(q * q for q in f[5:9]) - 1.0) < 1e-9


def test_script_runs_and_draws_every_frame(page):
    node = shutil.which("node")
    if node is None:
        pytest.skip("Node.js is not installed: the page's structure is checked above")
    out = subprocess.run([node, "-e", STUB, str(page)], check=True, capture_output=True, text=True)
    r = json.loads(out.stdout)
    html = page.read_text()
    n_frames = html.split("const FRAMES = [")[1].split("];")[0].count("[")
    n_path = html.split("const PATH = [")[1].split("];")[0].count(",") // 3 + 1
    # The first draw strokes the grey path (n_path − 1 segments), the 12 box edges and the trail,
    # and fills the nose face and the two points.
    assert r["first"]["stroke"] >= n_path - 1 + 12
    assert r["first"]["arc"] == 2
    assert r["after"]["stroke"] > r["first"]["stroke"]
    assert r["interval"] == 100  # 10 frames/s
    assert r["slider_max"] == n_frames - 1
    assert r["label"].startswith("t = ")


def test_page_draws_the_box_the_library_defines(page):
    # The box is defined once (imu_plot::scene) and handed to the page and to Python as data.
    html = page.read_text()
    body = json.loads("[" + html.split("const BODY = [")[1].split("]")[0] + "]")
    corners = json.loads(html.split("const CORNERS = ")[1].split(", EDGES")[0])
    edges = json.loads(html.split("EDGES = ")[1].split(", NOSE")[0])
    nose = json.loads(html.split("NOSE = ")[1].split(";")[0])
    import imukit

    py_corners, py_edges, py_nose = imukit._core.animation_scene(body)
    assert corners == py_corners.tolist()
    assert [tuple(e) for e in edges] == py_edges and nose == py_nose
    # The nose face is the box's +x face and the corners span the body.
    assert all(corners[i][0] == body[0] / 2 for i in nose)
    assert [max(c[k] for c in corners) - min(c[k] for c in corners) for k in range(3)] == body
