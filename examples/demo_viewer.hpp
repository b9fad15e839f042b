// SPDX-License-Identifier: MIT
// taxel-demo's interactive 3-D views: a small WebGL viewer of its own (no download, no server:
// the page works from file://). Each view is a <canvas> with its points embedded as JSON;
// drag to turn, wheel to zoom, double-click to reset. Points are coloured per point (by their
// error, or grey for a model), with x/y/z axes of a round length in millimetres.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <taxel/io/picture.hpp>
#include <vector>

namespace taxel_demo {

/// One layer of points in a view: positions [m], and an RGB colour per point.
struct Layer {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<std::uint8_t, 3>> colors;
  float size = 3.0f;  ///< point size in pixels
};

/// A layer coloured by `values` on taxel's ramp over [0, vmax].
inline Layer ramp_layer(const std::vector<Eigen::Vector3d>& points,
                        const std::vector<double>& values, double vmax) {
  Layer l;
  l.points = points;
  for (const double v : values) l.colors.push_back(taxel::io::ramp(vmax > 0 ? v / vmax : 0.0));
  return l;
}

/// A layer of one colour, at most `max_points` of `points` (evenly strided).
inline Layer plain_layer(const std::vector<Eigen::Vector3d>& points,
                         std::array<std::uint8_t, 3> rgb, std::size_t max_points, float size) {
  Layer l;
  l.size = size;
  const std::size_t step =
      std::max<std::size_t>(1, points.size() / std::max<std::size_t>(1, max_points));
  for (std::size_t i = 0; i < points.size(); i += step) {
    l.points.push_back(points[i]);
    l.colors.push_back(rgb);
  }
  return l;
}

/// The HTML of one view: a canvas, its data, and a colour bar when `bar_max` > 0 (the ramp from
/// 0 to bar_max, labelled with `bar_label`).
inline std::string view_html(const std::string& id, const std::string& caption,
                             const std::vector<Layer>& layers, double bar_max = 0.0,
                             const std::string& bar_label = "") {
  nlohmann::json data;
  nlohmann::json js_layers = nlohmann::json::array();
  for (const Layer& l : layers) {
    std::vector<double> p;
    std::vector<int> c;
    p.reserve(l.points.size() * 3);
    for (const auto& v : l.points) {
      for (int k = 0; k < 3; ++k) p.push_back(std::round(v[k] * 1e5) / 1e2);  // mm, 0.01 mm
    }
    for (const auto& rgb : l.colors) c.insert(c.end(), rgb.begin(), rgb.end());
    js_layers.push_back({{"p", p}, {"c", c}, {"size", l.size}});
  }
  data["layers"] = std::move(js_layers);
  std::string json = data.dump();
  for (std::size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at)) {
    json.replace(at, 2, "<\\/");
  }
  std::string h = "<figure class=\"view3d\"><div class=\"stage\"><canvas id=\"" + id +
                  "\" class=\"cloud3d\" width=\"480\" height=\"400\"></canvas></div>\n"
                  "<script type=\"application/json\" id=\"" +
                  id + "-data\">" + json + "</script>\n";
  if (bar_max > 0) {
    std::string stops;
    for (int k = 0; k <= 10; ++k) {
      const auto c = taxel::io::ramp(k / 10.0);
      stops += (k ? "," : "") + std::string("rgb(") + std::to_string(c[0]) + "," +
               std::to_string(c[1]) + "," + std::to_string(c[2]) + ")";
    }
    char hi[32];
    std::snprintf(hi, sizeof hi, "%.2f", bar_max);
    h += "<div class=\"bar\"><span>0</span><div style=\"background:linear-gradient(to right," +
         stops + ")\"></div><span>" + hi + " " + bar_label + "</span></div>\n";
  }
  h += "<figcaption>" + caption + "</figcaption></figure>\n";
  return h;
}

/// The viewer's script and style, once per page.
inline const char* viewer_script() {
  return R"js(<style>
.view3d .stage{position:relative;display:inline-block}
.view3d canvas{border:1px solid #ddd;cursor:grab;background:#fff}
.view3d .axis{position:absolute;font-size:11px;pointer-events:none}
.view3d .bar{display:flex;align-items:center;gap:.4em;font-size:.85em;max-width:480px}
.view3d .bar div{flex:1;height:10px;border:1px solid #bbb}
</style>
<script>
// A small WebGL point viewer: orthographic, depth-tested, turned by dragging.
function taxelView(canvas) {
  const data = JSON.parse(document.getElementById(canvas.id + '-data').textContent);
  const gl = canvas.getContext('webgl', {preserveDrawingBuffer: true, antialias: true});
  if (!gl) { canvas.dataset.status = 'no-webgl'; return; }
  const sh = (type, src) => { const s = gl.createShader(type); gl.shaderSource(s, src);
    gl.compileShader(s); return s; };
  const prog = gl.createProgram();
  gl.attachShader(prog, sh(gl.VERTEX_SHADER,
    'attribute vec3 p; attribute vec3 c; uniform mat4 m; uniform float s; varying vec3 v;' +
    'void main(){ gl_Position = m * vec4(p, 1.0); gl_PointSize = s; v = c; }'));
  gl.attachShader(prog, sh(gl.FRAGMENT_SHADER,
    'precision mediump float; varying vec3 v; void main(){ gl_FragColor = vec4(v, 1.0); }'));
  gl.linkProgram(prog);
  gl.useProgram(prog);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const l of data.layers) for (let i = 0; i < l.p.length; ++i) {
    lo[i % 3] = Math.min(lo[i % 3], l.p[i]); hi[i % 3] = Math.max(hi[i % 3], l.p[i]); }
  const mid = [0, 1, 2].map(k => (lo[k] + hi[k]) / 2);
  const radius = Math.max(1e-3, Math.hypot(...[0, 1, 2].map(k => (hi[k] - lo[k]) / 2))) * 1.05;
  // Axes from the low corner, of a round length in mm.
  const span = Math.max(...[0, 1, 2].map(k => hi[k] - lo[k]));
  const len = [1, 2, 5, 10, 20, 50, 100, 200, 500].find(v => v >= span / 3) || 1000;
  const axes = {p: [], c: []};
  const colors = [[0.85, 0.1, 0.1], [0.1, 0.6, 0.1], [0.1, 0.2, 0.9]];
  for (let k = 0; k < 3; ++k) {
    const end = lo.slice(); end[k] += len;
    axes.p.push(...lo, ...end); axes.c.push(...colors[k], ...colors[k]);
  }
  const buffer = (arr) => { const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(arr), gl.STATIC_DRAW); return b; };
  const layers = data.layers.map(l => ({p: buffer(l.p), c: buffer(l.c.map(x => x / 255)),
                                        n: l.p.length / 3, size: l.size}));
  const ax = {p: buffer(axes.p), c: buffer(axes.c), n: 6};
  const labels = ['x', 'y', 'z'].map((name, k) => {
    const d = document.createElement('span'); d.className = 'axis';
    d.style.color = 'rgb(' + colors[k].map(v => Math.round(255 * v)).join(',') + ')';
    d.textContent = name + (k === 0 ? ' ' + len + ' mm' : '');
    canvas.parentNode.appendChild(d); return d; });
  const P = gl.getAttribLocation(prog, 'p'), C = gl.getAttribLocation(prog, 'c');
  const M = gl.getUniformLocation(prog, 'm'), S = gl.getUniformLocation(prog, 's');
  let yaw = 0.6, pitch = -0.5, zoom = 1;
  const matrix = () => {
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    // rows of R = Rx(pitch) * Rz(yaw) (z up on screen after the pitch)
    const r = [[cy, -sy, 0], [sp * sy, sp * cy, cp], [cp * sy, cp * cy, -sp]];
    const s = zoom / radius, a = canvas.height / canvas.width;
    const m = new Float32Array(16);
    for (let i = 0; i < 3; ++i) {
      const sc = (i === 0 ? s * a : (i === 1 ? s : -0.5 / radius));
      for (let j = 0; j < 3; ++j) m[j * 4 + i] = r[i][j] * sc;
      m[12 + i] = -(r[i][0] * mid[0] + r[i][1] * mid[1] + r[i][2] * mid[2]) * sc;
    }
    m[15] = 1;
    return m;
  };
  const draw = () => {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.enable(gl.DEPTH_TEST);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const m = matrix();
    gl.uniformMatrix4fv(M, false, m);
    const bind = (o) => {
      gl.bindBuffer(gl.ARRAY_BUFFER, o.p); gl.enableVertexAttribArray(P);
      gl.vertexAttribPointer(P, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, o.c); gl.enableVertexAttribArray(C);
      gl.vertexAttribPointer(C, 3, gl.FLOAT, false, 0, 0); };
    for (const l of layers) { bind(l); gl.uniform1f(S, l.size); gl.drawArrays(gl.POINTS, 0, l.n); }
    bind(ax); gl.uniform1f(S, 1); gl.drawArrays(gl.LINES, 0, ax.n);
    for (let k = 0; k < 3; ++k) {  // the labels at the axes' ends
      const e = axes.p.slice(6 * k + 3, 6 * k + 6);
      const x = m[0] * e[0] + m[4] * e[1] + m[8] * e[2] + m[12];
      const y = m[1] * e[0] + m[5] * e[1] + m[9] * e[2] + m[13];
      labels[k].style.left = ((x + 1) / 2 * canvas.width + 3) + 'px';
      labels[k].style.top = ((1 - y) / 2 * canvas.height - 7) + 'px';
    }
  };
  let drag = null;
  canvas.addEventListener('mousedown', e => { drag = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', () => { drag = null; });
  window.addEventListener('mousemove', e => {
    if (!drag) return;
    yaw += (e.clientX - drag[0]) * 0.01; pitch += (e.clientY - drag[1]) * 0.01;
    drag = [e.clientX, e.clientY]; draw(); });
  canvas.addEventListener('wheel', e => { e.preventDefault();
    zoom *= Math.exp(-e.deltaY * 0.001); draw(); }, {passive: false});
  canvas.addEventListener('dblclick', () => { yaw = 0.6; pitch = -0.5; zoom = 1; draw(); });
  if (location.hash === '#solo=' + canvas.id) {  // this view alone (the page test's screenshot)
    for (const el of document.body.children) el.style.display = 'none';
    const top = canvas.closest('figure');
    top.style.display = 'block';
    top.style.margin = '0';
    for (const el of top.querySelectorAll('figcaption, .bar')) el.style.display = 'none';
    document.body.appendChild(top);
    document.body.style.margin = '0';
  }
  draw();
  // Self-check for the page test: how many pixels differ from the background.
  const px = new Uint8Array(canvas.width * canvas.height * 4);
  gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let inked = 0;
  for (let i = 0; i < px.length; i += 4) inked += (px[i] + px[i + 1] + px[i + 2] < 720) ? 1 : 0;
  canvas.dataset.inked = inked;
}
</script>
)js";
}

}  // namespace taxel_demo
