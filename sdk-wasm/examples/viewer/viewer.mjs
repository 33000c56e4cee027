// The viewer page's WebGL2 side: fetches the stream with ProgressiveMesh
// (stream.mjs), draws after the base level and after every round, and
// fetches further levels when the camera comes close enough for their
// detail to show (the screen-space error of the level table, SPEC §4.1).
//
// Query parameters: `stream` (URL of the .sps), `pixels` (largest screen
// error in pixels, default 1), `level` (decode up to this level whatever
// the view), `budget` (decoder memory cap in bytes), `geographic` (x and y
// are longitude and latitude in degrees, z in metres, as from `splitstream
// encode --geographic`: drawn in metres).
//
// `window.viewer` reports progress for scripts and tests: state
// ('loading', 'refining', 'idle', 'error'), levelsDone, levelCount,
// vertices, triangles, bytesFetched, hash, frames, error; and coverage(),
// which draws a frame and returns the fraction of pixels the mesh covers.
import init, { StreamDecoder } from './pkg/splitstream_sdk_wasm.js';
import { ProgressiveMesh } from './stream.mjs';

const params = new URLSearchParams(location.search);
const canvas = document.getElementById('view');
const statusLine = document.getElementById('status');
const report = (window.viewer = { state: 'loading', frames: 0 });
const FOV_Y = Math.PI / 4;

const VERTEX_SHADER = `#version 300 es
uniform mat4 viewProjection;
in vec3 position;
out vec3 world;
void main() {
  world = position;
  gl_Position = viewProjection * vec4(position, 1.0);
}`;

// Flat shading from screen-space derivatives: no normals to stream.
const FRAGMENT_SHADER = `#version 300 es
precision highp float;
uniform vec3 light;
in vec3 world;
out vec4 color;
void main() {
  vec3 n = normalize(cross(dFdx(world), dFdy(world)));
  float diffuse = abs(dot(n, light));
  color = vec4(vec3(0.16) + vec3(0.80, 0.74, 0.62) * diffuse, 1.0);
}`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
    throw new Error(gl.getShaderInfoLog(shader));
  }
  return shader;
}

function program(gl) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, VERTEX_SHADER));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT_SHADER));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

// Column-major 4 × 4 matrices, as WebGL takes them.
function perspective(fovY, aspect, near, far) {
  const f = 1 / Math.tan(fovY / 2);
  const m = new Float32Array(16);
  m[0] = f / aspect;
  m[5] = f;
  m[10] = (far + near) / (near - far);
  m[11] = -1;
  m[14] = (2 * far * near) / (near - far);
  return m;
}

function lookAt(eye, target, up) {
  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const norm = (a) => a.map((v) => v / Math.hypot(...a));
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, target));
  const x = norm(cross(up, z));
  const y = cross(z, x);
  return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
    -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
}

function multiply(a, b) {
  const m = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      m[c * 4 + r] = s;
    }
  }
  return m;
}

class Viewer {
  constructor(gl, mesh) {
    this.gl = gl;
    this.mesh = mesh;
    this.program = program(gl);
    this.vao = gl.createVertexArray();
    this.positions = gl.createBuffer();
    this.indices = gl.createBuffer();
    this.count = 0;
    this.yaw = 0.6;
    this.pitch = 0.5;
    this.refining = false;
    this.dirty = true;
  }

  /** Uploads the decoder's current mesh, relative to the model's centre
   *  (f32 cannot hold geographic coordinates, the offsets can). */
  upload() {
    const d = this.mesh.decoder;
    const p = d.positionsF64();
    if (this.centre === undefined) this.frame(p);
    const local = new Float32Array(p.length);
    for (let i = 0; i < p.length; i++) local[i] = (p[i] - this.centre[i % 3]) * this.scale[i % 3];
    const gl = this.gl;
    gl.bindVertexArray(this.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positions);
    gl.bufferData(gl.ARRAY_BUFFER, local, gl.DYNAMIC_DRAW);
    const at = gl.getAttribLocation(this.program, 'position');
    gl.enableVertexAttribArray(at);
    gl.vertexAttribPointer(at, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, d.indices(), gl.DYNAMIC_DRAW);
    this.count = 3 * d.triangleCount;
    this.dirty = true;
  }

  /** Centre, radius, up axis and a first distance from the base level. */
  frame(p) {
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; i++) {
      lo[i % 3] = Math.min(lo[i % 3], p[i]);
      hi[i % 3] = Math.max(hi[i % 3], p[i]);
    }
    this.centre = lo.map((v, k) => (v + hi[k]) / 2);
    // Metres per degree near the centre (spherical Earth), for geographic
    // streams; the stream itself does not say which it is.
    const lat = (this.centre[1] * Math.PI) / 180;
    this.scale = params.has('geographic') ? [111320 * Math.cos(lat), 110540, 1] : [1, 1, 1];
    const size = hi.map((v, k) => (v - lo[k]) * this.scale[k]);
    this.radius = Math.max(Math.hypot(...size) / 2, 1e-9);
    // Terrain lies flat in x, y: look down on it with z up; else y up.
    this.up = size[2] < 0.5 * Math.min(size[0], size[1]) ? [0, 0, 1] : [0, 1, 0];
    this.distance = 2.5 * this.radius;
  }

  eye() {
    const [cy, sy, cp, sp] = [Math.cos(this.yaw), Math.sin(this.yaw), Math.cos(this.pitch), Math.sin(this.pitch)];
    const r = this.distance;
    return this.up[2] === 1 ? [r * cp * cy, r * cp * sy, r * sp] : [r * cp * sy, r * sp, r * cp * cy];
  }

  /** The level this view needs: its error spans at most `pixels` pixels
   *  at the model's nearest point. */
  wantedLevel() {
    if (params.has('level')) return Math.min(Number(params.get('level')), this.mesh.levelCount - 1);
    return this.mesh.levelFor({
      viewportHeight: this.gl.drawingBufferHeight,
      fovY: FOV_Y,
      distance: Math.max(this.distance - this.radius, this.radius * 1e-3),
      maxPixels: Number(params.get('pixels') ?? 1),
    });
  }

  async refineTo(level) {
    this.refining = true;
    report.state = 'refining';
    try {
      for await (const _ of this.mesh.refine(level)) {
        this.upload();
        this.draw();
        showStatus(this.mesh);
        // One round per frame, so every round is seen.
        await new Promise(requestAnimationFrame);
      }
      this.upload();
    } finally {
      this.refining = false;
    }
  }

  draw() {
    const gl = this.gl;
    const width = Math.round(canvas.clientWidth * devicePixelRatio);
    const height = Math.round(canvas.clientHeight * devicePixelRatio);
    if (canvas.width !== width || canvas.height !== height) {
      [canvas.width, canvas.height] = [width, height];
      this.dirty = true;
    }
    if (!this.dirty) return;
    this.dirty = false;
    gl.viewport(0, 0, width, height);
    gl.clearColor(0.125, 0.137, 0.165, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    const near = Math.max(this.distance - this.radius, this.radius) * 0.01;
    const far = this.distance + 2 * this.radius;
    const vp = multiply(perspective(FOV_Y, width / height, near, far), lookAt(this.eye(), [0, 0, 0], this.up));
    gl.uniformMatrix4fv(gl.getUniformLocation(this.program, 'viewProjection'), false, vp);
    gl.uniform3fv(gl.getUniformLocation(this.program, 'light'), [0.36, 0.48, 0.8]);
    gl.bindVertexArray(this.vao);
    gl.drawElements(gl.TRIANGLES, this.count, gl.UNSIGNED_INT, 0);
    report.frames++;
  }

  controls() {
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      drag = [e.clientX, e.clientY];
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointerup', () => (drag = null));
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.yaw -= (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.dirty = true;
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      const factor = Math.exp(Math.sign(e.deltaY) * 0.1);
      this.distance = Math.max(this.radius * 1.01, this.distance * factor);
      this.dirty = true;
    }, { passive: false });
  }
}

function showStatus(mesh) {
  const d = mesh.decoder;
  Object.assign(report, {
    levelsDone: d.levelsDone,
    levelCount: mesh.levelCount,
    vertices: d.vertexCount,
    triangles: d.triangleCount,
    bytesFetched: mesh.bytesFetched,
    hash: d.stateHashHex(),
  });
  statusLine.textContent =
    `${params.get('stream')}\nlevels ${d.levelsDone}/${mesh.levelCount} decoded, ` +
    `${d.vertexCount} vertices, ${d.triangleCount} triangles, ` +
    `${mesh.bytesFetched} bytes fetched\nstate ${report.state}, hash ${report.hash}`;
}

async function main() {
  const url = params.get('stream');
  if (!url) throw new Error('no stream: add ?stream=URL-of-a-.sps-file to the address');
  const gl = canvas.getContext('webgl2', { antialias: true });
  if (!gl) throw new Error('this browser has no WebGL2');
  await init();
  const budget = params.get('budget');
  const mesh = await ProgressiveMesh.open(url, StreamDecoder,
    budget === null ? {} : { maxBytes: Number(budget) });
  const viewer = new Viewer(gl, mesh);
  viewer.controls();
  report.coverage = () => {
    // Read back in the same task as the draw: the drawing buffer is only
    // defined until the page composites it.
    viewer.dirty = true;
    viewer.draw();
    const [w, h] = [gl.drawingBufferWidth, gl.drawingBufferHeight];
    const pixels = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    let covered = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      // The clear colour is (32, 35, 42).
      if (Math.abs(pixels[i] - 32) + Math.abs(pixels[i + 1] - 35) + Math.abs(pixels[i + 2] - 42) > 6) covered++;
    }
    return covered / (w * h);
  };
  await viewer.refineTo(0);
  const tick = () => {
    if (!viewer.refining && viewer.wantedLevel() >= mesh.decoder.levelsDone) {
      viewer.refineTo(viewer.wantedLevel()).catch(fail);
    }
    if (!viewer.refining) report.state = 'idle';
    viewer.draw();
    showStatus(mesh);
    if (report.state !== 'error') requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}

function fail(e) {
  report.state = 'error';
  report.error = e.name === 'SplitstreamError' ? `${e.class}: ${e.message}` : String(e.message ?? e);
  statusLine.textContent = `error: ${report.error}`;
  console.error(e);
}

main().catch(fail);
