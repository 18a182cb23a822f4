// view3d.js — the mesh view of edgespace explore: three.js (served from the
// npm package tools/setup.sh installs, never from a CDN), one indexed mesh
// whose positions, normals and colours are replaced on every shape, drawn on
// demand (a new shape, a camera move), with a heat map and its colour bar.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { fmt } from './util.js';

// matplotlib's viridis at 11 stops (perceptually uniform, readable in grey)
const VIRIDIS = ['#440154', '#482475', '#414487', '#355f8d', '#2a788e', '#21918c',
  '#22a884', '#44bf70', '#7ad151', '#bddf26', '#fde725'].map((h) => new THREE.Color(h));
const BASE = new THREE.Color('#c9c2b8');

export function viridis(t, out) {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1);
  const i = Math.min(Math.floor(x), VIRIDIS.length - 2);
  return out.copy(VIRIDIS[i]).lerp(VIRIDIS[i + 1], x - i);
}

export class MeshView {
  // box: the element the canvas fills; colorbar: {box, canvas, min, max, label}
  constructor(box, colorbar, faces, nverts, view) {
    this.box = box;
    this.cb = colorbar;
    this.nverts = nverts;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0xffffff, 1);
    box.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(30, 1, 0.001, 1000);
    this.camera.add(new THREE.DirectionalLight(0xffffff, 2.2));
    this.scene.add(this.camera);
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.9));
    this.geometry = new THREE.BufferGeometry();
    this.geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(faces), 1));
    this.position = new THREE.BufferAttribute(new Float32Array(3 * nverts), 3);
    this.color = new THREE.BufferAttribute(new Float32Array(3 * nverts), 3);
    this.geometry.setAttribute('position', this.position);
    this.geometry.setAttribute('color', this.color);
    const material = new THREE.MeshStandardMaterial({
      vertexColors: true, roughness: 0.75, metalness: 0.0, side: THREE.DoubleSide });
    this.mesh = new THREE.Mesh(this.geometry, material);
    this.scene.add(this.mesh);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.draw());
    this.view = view;
    this.framed = false;
    new ResizeObserver(() => this.resize()).observe(box);
    this.resize();
  }

  resize() {
    const w = this.box.clientWidth || 400, h = this.box.clientHeight || 300;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.draw();
  }

  // Put the camera where the library's renderer would (es_render_auto_view),
  // far enough to see the whole first shape.
  frame() {
    this.geometry.computeBoundingSphere();
    const s = this.geometry.boundingSphere;
    const dir = new THREE.Vector3(...(this.view ? this.view.dir : [0, 0, 1])).normalize();
    const up = new THREE.Vector3(...(this.view ? this.view.up : [0, 1, 0])).normalize();
    const dist = s.radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 1.1;
    this.camera.up.copy(up);
    this.camera.position.copy(s.center).addScaledVector(dir, dist);
    this.camera.near = dist / 100;
    this.camera.far = dist * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(s.center);
    this.controls.update();
    this.framed = true;
  }

  // positions: Float64Array (3V); heat: Float64Array (V) or null with its
  // {min, max, label}. Returns once drawn.
  update(positions, heat, info) {
    this.position.array.set(positions);
    this.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
    this.geometry.computeBoundingSphere();
    this.setHeat(heat, info);
    if (!this.framed) this.frame();
    this.draw();
  }

  setHeat(heat, info) {
    const c = new THREE.Color(), a = this.color.array;
    const lo = info ? info.min : 0, hi = info ? info.max : 1, span = hi > lo ? hi - lo : 1;
    for (let v = 0; v < this.nverts; v++) {
      if (heat) viridis((heat[v] - lo) / span, c); else c.copy(BASE);
      a[3 * v] = c.r; a[3 * v + 1] = c.g; a[3 * v + 2] = c.b;
    }
    this.color.needsUpdate = true;
    this.cb.box.hidden = !heat;
    if (heat) {
      const g = this.cb.canvas.getContext('2d'), h = this.cb.canvas.height;
      for (let y = 0; y < h; y++) {
        viridis(1 - y / (h - 1), c);
        g.fillStyle = '#' + c.getHexString();
        g.fillRect(0, y, this.cb.canvas.width, 1);
      }
      this.cb.max.textContent = fmt(hi);
      this.cb.min.textContent = fmt(lo);
      this.cb.label.textContent = info.label;
    }
    this.heatInfo = heat ? info : null;
  }

  draw() {
    this.renderer.render(this.scene, this.camera);
  }

  // The view as PNG: the canvas, its colour bar and the point's expression.
  png(caption) {
    this.draw();
    const src = this.renderer.domElement, pad = 28;
    const out = document.createElement('canvas');
    out.width = src.width;
    out.height = src.height + pad;
    const g = out.getContext('2d');
    g.fillStyle = '#fff';
    g.fillRect(0, 0, out.width, out.height);
    g.drawImage(src, 0, 0);
    if (this.heatInfo) {
      const x = out.width - 70, y = 30, h = Math.min(200, src.height - 80);
      g.drawImage(this.cb.canvas, x, y, 16, h);
      g.strokeStyle = '#999';
      g.strokeRect(x, y, 16, h);
      g.fillStyle = '#333';
      g.font = '12px sans-serif';
      g.fillText(fmt(this.heatInfo.max), x + 20, y + 10);
      g.fillText(fmt(this.heatInfo.min), x + 20, y + h);
      wrap(g, this.heatInfo.label, x - 30, y + h + 16, 100);
    }
    g.fillStyle = '#222';
    g.font = '13px monospace';
    g.fillText(caption, 8, out.height - 9);
    return out.toDataURL('image/png');
  }
}

function wrap(g, text, x, y, width) {
  let line = '';
  for (const word of text.split(' ')) {
    if (g.measureText(line + word).width > width && line) {
      g.fillText(line, x, y);
      y += 14;
      line = '';
    }
    line += word + ' ';
  }
  g.fillText(line, x, y);
}
