// The 3-D view: the thread as a tube in the native viewer's colours and shading, the
// clamp, the grasp(s), the grip direction, the force arrow(s) and the self-contact pairs
// when the shape has them; orbit controls (left drag orbits, wheel zooms, right drag pans;
// F refits the camera).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import * as C from './colours.js';

// The page's colours are the viewer's numbers as they are: no sRGB conversion on input or
// output (the native viewer writes them straight into a plain framebuffer).
THREE.ColorManagement.enabled = false;

const TUBE_SIDES = 14;           // renderer.cc kTubeSides
const SAMPLES_PER_SEGMENT = 8;   // renderer.cc kSplineSamplesPerSegment

// The viewer's headlight: colour * (0.35 + 0.65 |n . view|), two-sided.
function headlightMaterial(rgb) {
  return new THREE.ShaderMaterial({
    uniforms: { colour: { value: new THREE.Vector3(...rgb) } },
    vertexShader: `varying vec3 vNormal;
      void main() {
        vNormal = normalize(normalMatrix * normal);
        gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
      }`,
    fragmentShader: `uniform vec3 colour; varying vec3 vNormal;
      void main() { gl_FragColor = vec4(colour * (0.35 + 0.65 * abs(normalize(vNormal).z)), 1.0); }`,
    side: THREE.DoubleSide,
  });
}

// An arrow of unit length along +y: shaft to 0.8, cone of 2.5 radii (mesh_builder.cc).
function makeArrow(rgb) {
  const material = headlightMaterial(rgb);
  const group = new THREE.Group();
  const shaft = new THREE.Mesh(new THREE.CylinderGeometry(1, 1, 1, 12), material);
  const head = new THREE.Mesh(new THREE.ConeGeometry(1, 1, 16), material);
  group.add(shaft, head);
  group.userData = { shaft, head };
  group.visible = false;
  return group;
}

const UP = new THREE.Vector3(0, 1, 0);
function placeArrow(arrow, from, to, radius) {
  const d = new THREE.Vector3().subVectors(to, from);
  const length = d.length();
  arrow.visible = length > 1e-12;
  if (!arrow.visible) return;
  const { shaft, head } = arrow.userData;
  shaft.scale.set(radius, 0.8 * length, radius);
  shaft.position.set(0, 0.4 * length, 0);
  head.scale.set(2.5 * radius, 0.2 * length, 2.5 * radius);
  head.position.set(0, 0.9 * length, 0);
  arrow.position.copy(from);
  arrow.quaternion.setFromUnitVectors(UP, d.divideScalar(length));
}

// A software rasteriser (SwiftShader, llvmpipe): multisampling would cost most of its
// frame rate, so the page draws without it there, as the native viewer does headless.
function softwareRenderer() {
  const gl = document.createElement('canvas').getContext('webgl2');
  const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  return /swiftshader|llvmpipe|software/i.test(name);
}

export class SceneView {
  constructor(canvas) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareRenderer() });
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(new THREE.Color(...C.BACKGROUND), 1);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 1e-3, 1e3);
    this.camera.position.set(0, 0, 3);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = false;
    this.dirty = true;  // something to draw: a new shape, a camera move, a resize
    this.controls.addEventListener('change', () => { this.dirty = true; });
    this.tube = null;
    this.tubeMaterials = new Map();  // by status
    this.sphere = new THREE.SphereGeometry(1, 20, 12);
    this.clamp = new THREE.Mesh(this.sphere, headlightMaterial(C.CLAMP));
    this.graspMaterial = headlightMaterial(C.GRASP);
    this.contactMaterial = headlightMaterial(C.CONTACT);
    this.grip = makeArrow(C.GRIP);
    this.scene.add(this.clamp, this.grip);
    this.grasps = [];   // spheres
    this.forces = [];   // arrows
    this.contacts = new THREE.Group();
    this.scene.add(this.contacts);
    this.forceScale = 0;  // the largest |F| seen (renderer.cc force_scale_n_)
    this.fitted = false;
    this.pending = null;  // the newest shape not drawn yet
    this.last = null;     // the shape drawn
    window.addEventListener('keydown', (e) => {
      if (e.key === 'f' || e.key === 'F') this.refit();
    });
  }

  refit() {
    this.fitted = false;
    if (!this.pending) this.pending = this.last;
    this.dirty = true;
  }

  // Keeps the newest shape; it is built into geometry at the next frame only.
  setShape(shape) {
    this.pending = shape;
    this.dirty = true;
  }

  material(status) {
    if (!this.tubeMaterials.has(status)) this.tubeMaterials.set(status, headlightMaterial(C.statusColour(status)));
    return this.tubeMaterials.get(status);
  }

  build(shape) {
    this.last = shape;
    const p = shape.positions;
    const nodes = [];
    for (let i = 0; i + 2 < p.length; i += 3) nodes.push(new THREE.Vector3(p[i], p[i + 1], p[i + 2]));
    if (nodes.length === 0) return;
    const box = new THREE.Box3().setFromPoints(nodes);
    const extent = Math.max(box.max.distanceTo(box.min), 1e-3);
    const radius = 0.012 * extent;
    if (this.tube) {
      this.scene.remove(this.tube);
      this.tube.geometry.dispose();
      this.tube = null;
    }
    if (nodes.length >= 2) {
      let curve, segments;
      if (shape.smooth) {
        curve = new THREE.CatmullRomCurve3(nodes, false, 'centripetal');
        segments = (nodes.length - 1) * SAMPLES_PER_SEGMENT;
      } else {  // a linkage: straight rods between the joints
        curve = new THREE.CurvePath();
        for (let i = 0; i + 1 < nodes.length; ++i) curve.add(new THREE.LineCurve3(nodes[i], nodes[i + 1]));
        segments = (nodes.length - 1) * 24;
      }
      this.tube = new THREE.Mesh(new THREE.TubeGeometry(curve, segments, radius, TUBE_SIDES, false),
                                 this.material(shape.status));
      this.scene.add(this.tube);
    }
    this.clamp.position.copy(nodes[0]);
    this.clamp.scale.setScalar(2.2 * radius);

    // Grasps: every one of a multi-grasp scene (point, force rows), else the single one.
    const g = shape.grasps && shape.grasps.length >= 6 ? shape.grasps : [...shape.grasp, ...shape.force];
    const count = Math.floor(g.length / 6);
    while (this.grasps.length < count) {
      const s = new THREE.Mesh(this.sphere, this.graspMaterial);
      const a = makeArrow(C.FORCE);
      this.grasps.push(s); this.forces.push(a); this.scene.add(s, a);
    }
    for (let i = 0; i < this.grasps.length; ++i) {
      const on = i < count;
      this.grasps[i].visible = on;
      this.forces[i].visible = false;
      if (!on) continue;
      const at = new THREE.Vector3(g[6 * i], g[6 * i + 1], g[6 * i + 2]);
      const f = new THREE.Vector3(g[6 * i + 3], g[6 * i + 4], g[6 * i + 5]);
      this.grasps[i].position.copy(at);
      this.grasps[i].scale.setScalar(2.0 * radius);
      // Length relative to the largest |F| seen, so any scene's force scale stays readable.
      const fn = f.length();
      this.forceScale = Math.max(this.forceScale, fn);
      if (fn > 1e-12 && this.forceScale > 0) {
        const len = 0.3 * extent * Math.min(Math.max(fn / this.forceScale, 0.05), 1.0);
        placeArrow(this.forces[i], at, at.clone().addScaledVector(f, len / fn), 0.6 * radius);
      }
    }
    const grip = new THREE.Vector3(...shape.grip);
    const grasp0 = new THREE.Vector3(g[0], g[1], g[2]);
    this.grip.visible = false;
    if (grip.length() > 1e-9) {
      placeArrow(this.grip, grasp0, grasp0.clone().addScaledVector(grip.normalize(), 0.12 * extent), 0.5 * radius);
    }
    this.buildContacts(shape.contacts || [], radius);
    if (!this.fitted) this.fit(box, extent);
  }

  // Each active pair: the two closest points and the segment between them.
  buildContacts(c, radius) {
    for (const child of [...this.contacts.children]) {
      if (child.geometry !== this.sphere) child.geometry.dispose();
      this.contacts.remove(child);
    }
    for (let i = 0; i + 5 < c.length; i += 6) {
      const a = new THREE.Vector3(c[i], c[i + 1], c[i + 2]);
      const b = new THREE.Vector3(c[i + 3], c[i + 4], c[i + 5]);
      for (const at of [a, b]) {
        const s = new THREE.Mesh(this.sphere, this.contactMaterial);
        s.position.copy(at);
        s.scale.setScalar(1.3 * radius);
        this.contacts.add(s);
      }
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints([a, b]),
                                  new THREE.LineBasicMaterial({ color: new THREE.Color(...C.CONTACT) }));
      this.contacts.add(line);
    }
  }

  fit(box, extent) {
    const centre = box.getCenter(new THREE.Vector3());
    this.controls.target.copy(centre);
    // Far enough back for the force arrow (up to 0.3 extent past the grasp) to stay in view.
    this.camera.position.set(centre.x, centre.y, centre.z + 2.0 * extent);
    this.camera.near = extent * 1e-3;
    this.camera.far = extent * 100;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.fitted = true;
    this.dirty = true;
  }

  resize() {
    const canvas = this.renderer.domElement;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.floor(w * this.renderer.getPixelRatio()) ||
        canvas.height !== Math.floor(h * this.renderer.getPixelRatio())) {
      this.renderer.setSize(w, h, false);
      this.camera.aspect = w / Math.max(h, 1);
      this.camera.updateProjectionMatrix();
      this.dirty = true;
    }
  }

  // One frame: builds the newest shape if one came and renders, when anything changed
  // (a still session costs no drawing). True when drawn.
  draw() {
    this.resize();
    if (!this.dirty) return false;
    this.dirty = false;
    if (this.pending) {
      this.build(this.pending);
      this.pending = null;
    }
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
    return true;
  }
}
