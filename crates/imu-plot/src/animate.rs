//! `imukit animate`: the rigid body moving along its path (the MATLAB trajectory tool's `my_traAnim`).
//!
//! The body is a box of the given size centred on the reference point S, turned by the truth's
//! attitude; its nose face (body +x) is filled. The reference point (yellow) and the IMU point at
//! the lever arm (violet) are marked, the path already travelled is drawn over the whole path.
//! Frames are taken at `fps` frames per second of animation time, `speed` seconds of motion per
//! second of animation (by default chosen so the animation lasts at most about 12 s).
use std::path::Path;

use crate::spec::{FramePlan, default_body_m, frame_plan};
use imukit::Table;
use plotters::prelude::*;

use crate::draw::{COLORS, err, every, rasterise, stride_for};
use crate::scene::{BOX_EDGES, BOX_NOSE, body_point_enu, box_corners_m, pose_enu};
use crate::{FigureOption, PlotError};

/// Animation settings.
#[derive(Clone, Copy, Debug)]
pub struct AnimateOptions {
    /// Box length, width, height (body x, y, z), m; `None`: a tenth of the path's extent long,
    /// half as wide, a quarter as high.
    pub body_m: Option<[f64; 3]>,
    /// Lever arm of the IMU point from the reference point, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// Frames per second of the animation.
    pub fps: f64,
    /// Seconds of motion per second of animation; `None` chooses one.
    pub speed: Option<f64>,
    /// Image size, pixels.
    pub size: (u32, u32),
    /// The truth is in NED (drawn turned into ENU so that up is up); else ENU.
    pub ned: bool,
}

impl Default for AnimateOptions {
    fn default() -> Self {
        Self {
            body_m: None,
            lever_arm_m: [0.0; 3],
            fps: 20.0,
            speed: None,
            ned: false,
            size: (560, 420),
        }
    }
}

/// What was written.
#[derive(Clone, Copy, Debug)]
pub struct AnimationInfo {
    /// Number of frames.
    pub frames: usize,
    /// Seconds of motion per second of animation.
    pub speed: f64,
}

struct Pose {
    t: f64,
    p: [f64; 3],
    q: [f64; 4],
}

/// Reads the poses, checking positions and quaternions per row (times: [`frame_plan`]); NED
/// poses are turned into ENU ones (the body axes stay those of the data).
fn poses(truth: &Table, source: &str, ned: bool) -> Result<Vec<Pose>, PlotError> {
    let bad = |at: String, message: String| PlotError::Invalid { field: at, message };
    let col = |c: &str| {
        truth.column(c).ok_or_else(|| {
            let message = format!("no {c} column: animate needs a truth CSV (t_s, pos_*_m, q_*)");
            bad(source.into(), message)
        })
    };
    let (t, x, y, z) = (
        col("t_s")?,
        col("pos_x_m")?,
        col("pos_y_m")?,
        col("pos_z_m")?,
    );
    let (qw, qx, qy, qz) = (col("q_w")?, col("q_x")?, col("q_y")?, col("q_z")?);
    let mut out = Vec::with_capacity(t.len());
    for i in 0..t.len() {
        let row = format!("{source}, row {}", i + 2);
        let p = [x[i], y[i], z[i]];
        let q = [qw[i], qx[i], qy[i], qz[i]];
        if !(t[i].is_finite() && p.iter().chain(&q).all(|v| v.is_finite())) {
            return Err(bad(
                row,
                "time, position and quaternion must be finite numbers".into(),
            ));
        }
        let (p, q) =
            pose_enu(p, q, ned).ok_or_else(|| bad(row.clone(), "the quaternion is zero".into()))?;
        let pose = Pose { t: t[i], p, q };
        out.push(pose);
    }
    Ok(out)
}

/// At most this many points of the path are drawn.
const PATH_POINTS: usize = 2000;

/// Everything a frame needs, resolved from the truth and the options.
struct Scene {
    poses: Vec<Pose>,
    frames: Vec<usize>,
    body: [f64; 3],
    lever: [f64; 3],
    speed: f64,
    /// Every `stride`-th pose is a path point.
    stride: usize,
    /// Per-axis bounds of the path, padded by the body.
    bounds: [(f64, f64); 3],
}

impl Scene {
    fn new(truth: &Table, source: &str, opts: &AnimateOptions) -> Result<Self, PlotError> {
        let bad = |option, message: &str| PlotError::Option {
            option,
            message: message.into(),
        };
        let finite3 = |v: [f64; 3]| v.iter().all(|x| x.is_finite());
        if opts
            .body_m
            .is_some_and(|b| !(finite3(b) && b.iter().all(|v| *v > 0.0)))
        {
            return Err(bad(
                FigureOption::Body,
                "length, width and height must be positive",
            ));
        }
        if !finite3(opts.lever_arm_m) {
            return Err(bad(FigureOption::LeverArm, "must be finite"));
        }
        let poses = poses(truth, source, opts.ned)?;
        let times: Vec<f64> = poses.iter().map(|p| p.t).collect();
        let FramePlan {
            indices: frames,
            speed,
        } = frame_plan(&times, opts.fps, opts.speed, source)?;
        let raw: [(f64, f64); 3] = core::array::from_fn(|k| {
            poses
                .iter()
                .map(|p| p.p[k])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                })
        });
        let extent = raw.iter().map(|(lo, hi)| hi - lo).fold(0.0_f64, f64::max);
        let body = opts.body_m.unwrap_or_else(|| default_body_m(extent));
        let pad = body
            .iter()
            .chain(&opts.lever_arm_m)
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let stride = stride_for(poses.len(), PATH_POINTS);
        Ok(Self {
            frames,
            body,
            lever: opts.lever_arm_m,
            speed,
            stride,
            bounds: raw.map(|(lo, hi)| (lo - pad, hi + pad)),
            poses,
        })
    }

    /// The path points (every `stride`-th pose and the last).
    fn path(&self) -> Vec<[f64; 3]> {
        every(
            &self.poses.iter().map(|p| p.p).collect::<Vec<_>>(),
            self.stride,
        )
    }
}

/// The kinds of animation file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationFormat {
    /// `.gif`.
    Gif,
    /// `.html` or `.htm`: a self-contained page.
    Html,
}

/// The format an animation path asks for, by extension; checked before any work.
///
/// # Errors
/// [`PlotError::Draw`] for another extension.
pub fn check_animation_path(out: &Path) -> Result<AnimationFormat, PlotError> {
    match out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("gif") => Ok(AnimationFormat::Gif),
        Some("html" | "htm") => Ok(AnimationFormat::Html),
        _ => Err(PlotError::Draw {
            path: out.display().to_string(),
            message: "the animation file must end in .gif or .html".into(),
        }),
    }
}

/// Writes a GIF (`.gif`) or a self-contained HTML page (`.html`) animating `truth` (read from
/// `source`, named in errors).
///
/// # Errors
/// Missing columns, fewer than 2 rows, non-finite or non-increasing rows, bad options, unknown
/// output extension, I/O.
pub fn animate(
    truth: &Table,
    source: &str,
    out: &Path,
    opts: &AnimateOptions,
) -> Result<AnimationInfo, PlotError> {
    let fail = |message: String| PlotError::Draw {
        path: out.display().to_string(),
        message,
    };
    let format = check_animation_path(out)?;
    let scene = Scene::new(truth, source, opts)?;
    let bytes = match format {
        AnimationFormat::Gif => gif(&scene, opts).map_err(fail)?,
        AnimationFormat::Html => html(&scene, opts).into_bytes(),
    };
    imukit::io::output::write_atomically(out, |w| std::io::Write::write_all(w, &bytes))?;
    Ok(AnimationInfo {
        frames: scene.frames.len(),
        speed: scene.speed,
    })
}

/// Plotters' 3D axes are (x, y up, z): the navigation (x, y, z) goes to (x, z, y).
fn up(p: [f64; 3]) -> (f64, f64, f64) {
    (p[0], p[2], p[1])
}

fn gif(scene: &Scene, opts: &AnimateOptions) -> Result<Vec<u8>, String> {
    let (w, h) = opts.size;
    let [bx, by, bz] = scene.bounds;
    let delay = (100.0 / opts.fps).round().max(1.0) as u16;
    let path: Vec<(f64, f64, f64)> = scene.path().into_iter().map(up).collect();
    let mut bytes = Vec::new();
    {
        let mut encoder = gif::Encoder::new(&mut bytes, w as u16, h as u16, &[]).map_err(err)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(err)?;
        for (k, &i) in scene.frames.iter().enumerate() {
            let pose = &scene.poses[i];
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(err)?;
                let mut chart = ChartBuilder::on(&root)
                    .margin(6)
                    .build_cartesian_3d(bx.0..bx.1, bz.0..bz.1, by.0..by.1)
                    .map_err(err)?;
                chart.with_projection(|mut p| {
                    p.pitch = 0.5;
                    p.yaw = 0.6;
                    p.scale = 0.85;
                    p.into_matrix()
                });
                chart.configure_axes().draw().map_err(err)?;
                chart
                    .draw_series(LineSeries::new(
                        path.clone(),
                        RGBColor(190, 190, 190).stroke_width(1),
                    ))
                    .map_err(err)?;
                let mut trail = path[..=i / scene.stride].to_vec();
                trail.push(up(pose.p));
                chart
                    .draw_series(LineSeries::new(trail, COLORS[0].stroke_width(2)))
                    .map_err(err)?;
                let c: Vec<(f64, f64, f64)> = box_corners_m(scene.body)
                    .iter()
                    .map(|c| up(body_point_enu(pose.p, pose.q, *c)))
                    .collect();
                chart
                    .draw_series([Polygon::new(
                        BOX_NOSE.map(|j| c[j]).to_vec(),
                        COLORS[3].mix(0.5).filled(),
                    )])
                    .map_err(err)?;
                chart
                    .draw_series(BOX_EDGES.iter().map(|&(a, b)| {
                        PathElement::new(vec![c[a], c[b]], COLORS[3].stroke_width(2))
                    }))
                    .map_err(err)?;
                let imu = body_point_enu(pose.p, pose.q, scene.lever);
                chart
                    .draw_series([Circle::new(up(pose.p), 5, RGBColor(230, 190, 0).filled())])
                    .map_err(err)?;
                chart
                    .draw_series([Circle::new(up(imu), 4, COLORS[4].filled())])
                    .map_err(err)?;
                let caption = format!(
                    "t = {:.2} s · {}× real time · x east, y north, z up (m)",
                    pose.t, scene.speed
                );
                root.draw(&Text::new(caption, (10, 8), ("sans-serif", 13)))
                    .map_err(err)?;
                let key =
                    "box: the body, nose face filled · yellow: reference point · violet: IMU point";
                root.draw(&Text::new(key, (10, 26), ("sans-serif", 11)))
                    .map_err(err)?;
                root.present().map_err(err)?;
            }
            let pixmap = rasterise(&svg, w, h)?;
            let mut rgba = pixmap.data().to_vec();
            let mut frame = gif::Frame::from_rgba_speed(w as u16, h as u16, &mut rgba, 10);
            frame.delay = delay;
            encoder
                .write_frame(&frame)
                .map_err(|e| format!("frame {k}: {e}"))?;
        }
    }
    Ok(bytes)
}

fn html(scene: &Scene, opts: &AnimateOptions) -> String {
    let num = |v: f64| zmij::Buffer::new().format(v).to_string();
    let list = |v: &[f64]| v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(",");
    let path = scene
        .path()
        .iter()
        .map(|p| list(p))
        .collect::<Vec<_>>()
        .join(",");
    let frame_data = scene
        .frames
        .iter()
        .map(|&i| {
            let p = &scene.poses[i];
            format!(
                "[{},{},{},{}]",
                num(p.t),
                i / scene.stride + 1,
                list(&p.p),
                list(&p.q)
            )
        })
        .collect::<Vec<_>>()
        .join(",");
    let nested = |items: &[String]| {
        let inner: Vec<String> = items.iter().map(|x| format!("[{x}]")).collect();
        format!("[{}]", inner.join(","))
    };
    let (w, h) = opts.size;
    HTML_TEMPLATE
        .replace("@WIDTH@", &w.to_string())
        .replace("@HEIGHT@", &h.to_string())
        .replace("@PATH@", &path)
        .replace("@FRAMES@", &frame_data)
        .replace("@BODY@", &list(&scene.body))
        .replace(
            "@CORNERS@",
            &nested(&box_corners_m(scene.body).map(|c| list(&c))),
        )
        .replace(
            "@EDGES@",
            &nested(&BOX_EDGES.map(|(a, b)| format!("{a},{b}"))),
        )
        .replace(
            "@NOSE@",
            &format!("[{}]", BOX_NOSE.map(|i| i.to_string()).join(",")),
        )
        .replace("@LEVER@", &list(&scene.lever))
        .replace("@FPS@", &num(opts.fps))
        .replace("@SPEED@", &num(scene.speed))
}

const HTML_TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>imukit animation</title>
<style>body{font-family:sans-serif;margin:16px}canvas{border:1px solid #ccc}</style></head>
<body>
<h3>imukit: rigid body along its path</h3>
<canvas id="view" width="@WIDTH@" height="@HEIGHT@"></canvas>
<div><button id="play">pause</button> <input id="slider" type="range" min="0" value="0" style="width:60%">
<span id="time"></span></div>
<p>Box: the body (nose face filled); yellow: reference point S; violet: IMU point at the lever arm;
grey: the path; blue: the path travelled. Drag with the mouse to turn the view.</p>
<script>
"use strict";
const PATH = [@PATH@];
const FRAMES = [@FRAMES@];
const BODY = [@BODY@], LEVER = [@LEVER@], FPS = @FPS@, SPEED = @SPEED@;
const CORNERS = @CORNERS@, EDGES = @EDGES@, NOSE = @NOSE@;
const canvas = document.getElementById("view"), ctx = canvas.getContext("2d");
const slider = document.getElementById("slider"), label = document.getElementById("time");
slider.max = FRAMES.length - 1;
let yaw = 0.6, pitch = 0.5, frame = 0, playing = true;
function rotate(q, v) { const [w, x, y, z] = q;
  const t = [2*(y*v[2]-z*v[1]), 2*(z*v[0]-x*v[2]), 2*(x*v[1]-y*v[0])];
  return [v[0]+w*t[0]+(y*t[2]-z*t[1]), v[1]+w*t[1]+(z*t[0]-x*t[2]), v[2]+w*t[2]+(x*t[1]-y*t[0])]; }
const pts = []; for (let i = 0; i < PATH.length; i += 3) pts.push([PATH[i], PATH[i+1], PATH[i+2]]);
const lo = [0,1,2].map(k => Math.min(...pts.map(p => p[k]))), hi = [0,1,2].map(k => Math.max(...pts.map(p => p[k])));
const centre = [0,1,2].map(k => (lo[k] + hi[k]) / 2);
const span = Math.max(...[0,1,2].map(k => hi[k] - lo[k]), ...BODY) * 1.2;
function project(p) { const d = [p[0]-centre[0], p[1]-centre[1], p[2]-centre[2]];
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const x = cy*d[0] - sy*d[1], y = sy*d[0] + cy*d[1];
  const s = Math.min(canvas.width, canvas.height) / span;
  return [canvas.width/2 + s*x, canvas.height/2 - s*(cp*d[2] - sp*y)]; }
function line(a, b, colour, width) { const p = project(a), q = project(b);
  ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke(); }
function dot(p, colour, r) { const q = project(p); ctx.fillStyle = colour; ctx.beginPath(); ctx.arc(q[0], q[1], r, 0, 7); ctx.fill(); }
function draw() {
  const f = FRAMES[frame], t = f[0], travelled = f[1], s = [f[2], f[3], f[4]], q = [f[5], f[6], f[7], f[8]];
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  for (let i = 1; i < pts.length; i++) line(pts[i-1], pts[i], "#bbb", 1);
  for (let i = 1; i < travelled; i++) line(pts[i-1], pts[i], "#1f77b4", 2);
  if (travelled > 0) line(pts[travelled-1], s, "#1f77b4", 2);
  const c = CORNERS.map(b => { const r = rotate(q, b); return [s[0]+r[0], s[1]+r[1], s[2]+r[2]]; });
  const nose = NOSE.map(i => project(c[i])); ctx.fillStyle = "rgba(214,39,40,0.5)"; ctx.beginPath();
  ctx.moveTo(...nose[0]); nose.slice(1).forEach(p => ctx.lineTo(...p)); ctx.closePath(); ctx.fill();
  EDGES.forEach(([a,b]) => line(c[a], c[b], "#d62728", 2));
  const l = rotate(q, LEVER); dot(s, "#e6be00", 5); dot([s[0]+l[0], s[1]+l[1], s[2]+l[2]], "#9467bd", 4);
  slider.value = frame; label.textContent = "t = " + t.toFixed(2) + " s (" + SPEED + "× real time)"; }
function tick() { if (playing) { frame = (frame + 1) % FRAMES.length; draw(); } }
document.getElementById("play").onclick = e => { playing = !playing; e.target.textContent = playing ? "pause" : "play"; };
slider.oninput = () => { frame = +slider.value; draw(); };
let drag = null; canvas.onmousedown = e => drag = [e.clientX, e.clientY, yaw, pitch];
window.onmouseup = () => drag = null;
window.onmousemove = e => { if (drag) { yaw = drag[2] + (e.clientX - drag[0]) / 150; pitch = drag[3] + (e.clientY - drag[1]) / 150; draw(); } };
draw(); setInterval(tick, 1000 / FPS);
</script></body></html>
"##;
