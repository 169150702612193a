// hapticsim view: draws a running hapticsimd's object, tool and force from the messages that
// `hapticsim view` forwards from LCM over a WebSocket (see tools/view/view_feed.cpp for their
// fields). Object frame: the object is a box of lattice nodes from 0 to its largest index times
// spacing on each axis (the paper's cube: n - 1 on all three); node ids are (ix·n + iy)·n + iz with
// n = nodes_per_axis, the largest node count. All lengths are metres, forces newtons.
import * as THREE from 'three';
import { OrbitControls } from '/OrbitControls.js';

const JND_PERCENT = 7;  // the force-magnitude JND the error map is judged against (docs/error-map.md)
const PRIMARY_COLOR = new THREE.Color(0xe8894a);
const SECONDARY_COLOR = new THREE.Color(0x7d93b0);

const $ = (id) => document.getElementById(id);

// ---- three.js scene --------------------------------------------------------------------------
const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
$('scene').appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1d2127);
scene.add(new THREE.HemisphereLight(0xdde6f0, 0x30343a, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 1e-3, 100);
camera.up.set(0, -1, 0);  // object y downwards on the screen: x to the right, the front face ahead
const controls = new OrbitControls(camera, renderer.domElement);

const surfaceMaterial = new THREE.MeshStandardMaterial({
  vertexColors: true, flatShading: true, side: THREE.DoubleSide, roughness: 0.75 });
const latticeMaterial = new THREE.LineBasicMaterial({ color: 0x000000, transparent: true,
                                                     opacity: 0.22 });
const tool = new THREE.Mesh(new THREE.SphereGeometry(1, 24, 16),
                            new THREE.MeshStandardMaterial({ color: 0xf5f5f5, emissive: 0x555555 }));
tool.visible = false;
scene.add(tool);

// The force arrow: a shaft and a head of unit size along +y, scaled and turned each frame.
const arrowMaterial = new THREE.MeshStandardMaterial({ color: 0xffd24a, emissive: 0x6b5200 });
const arrow = new THREE.Group();
const shaft = new THREE.Mesh(new THREE.CylinderGeometry(1, 1, 1, 12), arrowMaterial);
const head = new THREE.Mesh(new THREE.ConeGeometry(1, 1, 16), arrowMaterial);
arrow.add(shaft, head);
arrow.visible = false;
scene.add(arrow);
const Y_AXIS = new THREE.Vector3(0, 1, 0);

function pointArrow(from, force, metresPerNewton, thickness) {
  const length = force.length() * metresPerNewton;
  const headLength = Math.min(0.35 * length, 5 * thickness);
  arrow.position.copy(from);
  arrow.quaternion.setFromUnitVectors(Y_AXIS, force.clone().normalize());
  shaft.scale.set(thickness, length - headLength, thickness);
  shaft.position.y = (length - headLength) / 2;
  head.scale.set(2.5 * thickness, headLength, 2.5 * thickness);
  head.position.y = length - headLength / 2;
}

// ---- the object, built from the first deformation frame of a configuration -------------------
// nodes: one position per surface node (what the lattice lines and the tool read); surface: six
// vertices per lattice square, so each square is coloured by the region it belongs to, sharply.
const object = {
  n: 0, last: [0, 0, 0], spacing: 0, edge: 0, configuration: -1, ids: null, rest: null, quads: null,
  nodes: null, segments: null, surface: null, lattice: null, primaryBox: null, contactIndex: -1,
};
let arrowMetresPerNewton = 0.05;

function nodeLattice(id, n) { return [Math.floor(id / (n * n)), Math.floor(id / n) % n, id % n]; }

// The lattice squares on the box's six faces (its largest index per axis: last), as four node
// indices each, wound outwards.
function surfaceQuads(n, last, indexOf) {
  const quads = [];
  for (let a = 0; a < 3; ++a) {
    const b = (a + 1) % 3, c = (a + 2) % 3;
    for (const side of [0, last[a]]) {
      for (let i = 0; i < last[b]; ++i) {
        for (let j = 0; j < last[c]; ++j) {
          const corner = (di, dj) => {
            const ijk = [0, 0, 0];
            ijk[a] = side; ijk[b] = i + di; ijk[c] = j + dj;
            return indexOf.get((ijk[0] * n + ijk[1]) * n + ijk[2]);
          };
          const q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
          if (q.some((v) => v === undefined)) continue;
          quads.push(...(side === last[a] ? q : [q[0], q[3], q[2], q[1]]));
        }
      }
    }
  }
  return quads;
}

// The object's own faces (hapticsim view --scene: four node ids each, wound outwards) as node
// indices; a face with a node the frame does not carry is left out.
function objectQuads(faceIds, indexOf) {
  const quads = [];
  for (let q = 0; q < faceIds.length; q += 4) {
    const corners = faceIds.slice(q, q + 4).map((id) => indexOf.get(id));
    if (corners.every((v) => v !== undefined)) quads.push(...corners);
  }
  return quads;
}

const QUAD_TRIANGLES = [0, 1, 2, 0, 2, 3];

function quadLines(quads) {
  const seen = new Set(), lines = [];
  for (let q = 0; q < quads.length; q += 4) {
    for (let k = 0; k < 4; ++k) {
      const a = quads[q + k], b = quads[q + (k + 1) % 4];
      const key = a < b ? a * 1e6 + b : b * 1e6 + a;
      if (!seen.has(key)) { seen.add(key); lines.push(a, b); }
    }
  }
  return lines;
}

function buildObject(m) {
  for (const mesh of [object.surface, object.lattice, object.primaryBox]) {
    if (!mesh) continue;
    scene.remove(mesh);
    mesh.geometry?.dispose();
  }
  const n = m.nodes_per_axis, h = m.spacing_m, ids = m.node_ids;
  const indexOf = new Map(ids.map((id, k) => [id, k]));
  const rest = new Float32Array(3 * ids.length), last = [0, 0, 0];
  ids.forEach((id, k) => nodeLattice(id, n).forEach((l, c) => {
    rest[3 * k + c] = l * h;
    last[c] = Math.max(last[c], l);
  }));
  const quads = hello.surfaceQuads && hello.nodesPerAxis === n
    ? objectQuads(hello.surfaceQuads, indexOf) : surfaceQuads(n, last, indexOf);
  // Surface nodes no square drawn has: an object that leaves voxels of its box empty, drawn as a
  // box (its own faces come with --scene).
  const drawn = new Set(quads);
  object.undrawnNodes = ids.length - drawn.size;
  const nodes = new THREE.BufferAttribute(rest.slice(), 3);
  const lines = new THREE.BufferGeometry();
  lines.setAttribute('position', nodes);
  const surface = new THREE.BufferGeometry();
  const vertices = (quads.length / 4) * 6;
  surface.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * vertices), 3));
  surface.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * vertices), 3));
  Object.assign(object, {
    n, last, spacing: h, edge: Math.max(...last) * h, configuration: m.configuration_id, ids, rest,
    quads, nodes,
    segments: quadLines(quads),
    surface: new THREE.Mesh(surface, surfaceMaterial),
    lattice: new THREE.LineSegments(lines, latticeMaterial),
  });
  scene.add(object.surface, object.lattice);
  colourRegions(m);
  if (!controls.userMoved) frameCamera();
}

// The primary region: the coarse cells (secondary_lod fine cells a side) that overlap the box of
// the contact node ± primary_size, clipped to the object — core/regions/region_partition.cpp makes the
// box, core/regions/hybrid_mesh.cpp's CellOverlaps takes the cells. Its extent in lattice indices.
function primaryExtent(m, last) {
  const k = Math.max(1, m.secondary_lod), r = m.primary_size;
  const lo = [], hi = [];
  m.contact_node.forEach((c, a) => {
    const boxLo = Math.max(0, c - r), boxHi = Math.min(last[a], c + r);
    let first = Infinity, end = -Infinity;
    for (let j = 0; j * k < last[a]; ++j) {
      if (j * k < boxHi && (j + 1) * k > boxLo) { first = Math.min(first, j * k); end = (j + 1) * k; }
    }
    lo.push(first); hi.push(Math.min(end, last[a]));  // a coarse cell past the object: clipped
  });
  return { lo, hi };
}

// A square with all four corners in the primary's extent is the primary's, every other square a
// coarser secondary region's. The lattice lines drawn: every line in the primary, every
// secondary_lod-th line elsewhere.
function colourRegions(m) {
  if (object.primaryBox) {
    scene.remove(object.primaryBox);
    object.primaryBox.geometry.dispose();
  }
  const n = object.n;
  const { lo, hi } = primaryExtent(m, object.last);
  object.primary = { lo, hi };
  const inPrimary = (k) => nodeLattice(object.ids[k], n).every((v, a) => v >= lo[a] && v <= hi[a]);
  const colours = object.surface.geometry.attributes.color;
  for (let q = 0; q < object.quads.length; q += 4) {
    const primary = [0, 1, 2, 3].every((k) => inPrimary(object.quads[q + k]));
    const colour = primary ? PRIMARY_COLOR : SECONDARY_COLOR;
    for (let v = 0; v < 6; ++v) colour.toArray(colours.array, 3 * ((q / 4) * 6 + v));
  }
  colours.needsUpdate = true;
  const lod = Math.max(1, m.secondary_lod), drawn = [];
  for (let k = 0; k < object.segments.length; k += 2) {
    const a = object.segments[k], b = object.segments[k + 1];
    const la = nodeLattice(object.ids[a], n), lb = nodeLattice(object.ids[b], n);
    const onCoarseLine = la.every((v, axis) => v !== lb[axis] || v % lod === 0);
    if (onCoarseLine || (inPrimary(a) && inPrimary(b))) drawn.push(a, b);
  }
  object.lattice.geometry.setIndex(drawn);
  const c = m.contact_node;
  object.contactIndex = object.ids.indexOf((c[0] * n + c[1]) * n + c[2]);
  const h = object.spacing;
  const box = new THREE.Box3(new THREE.Vector3(...lo).multiplyScalar(h),
                             new THREE.Vector3(...hi).multiplyScalar(h));
  object.primaryBox = new THREE.Box3Helper(box, 0xffd0a8);
  scene.add(object.primaryBox);
}

// Rest positions plus this frame's displacements, into the nodes and the squares' vertices.
function displace(displacement) {
  const nodes = object.nodes.array, rest = object.rest;
  for (let k = 0; k < nodes.length; ++k) nodes[k] = rest[k] + displacement[k];
  object.nodes.needsUpdate = true;
  const position = object.surface.geometry.attributes.position, p = position.array;
  for (let q = 0, v = 0; q < object.quads.length; q += 4) {
    for (const corner of QUAD_TRIANGLES) {
      const node = object.quads[q + corner];
      p[v++] = nodes[3 * node]; p[v++] = nodes[3 * node + 1]; p[v++] = nodes[3 * node + 2];
    }
  }
  position.needsUpdate = true;
  object.surface.geometry.computeBoundingSphere();
  object.lattice.geometry.computeBoundingSphere();
}

function frameCamera() {
  // From the front, above and to the right, the object right of the panel.
  const e = object.edge, target = new THREE.Vector3(0.2 * e, 0.5 * e, 0.5 * e);
  camera.position.copy(target).add(new THREE.Vector3(0.85 * e, -0.8 * e, -2.2 * e));
  controls.target.copy(target);
  controls.update();
  sun.position.set(e * 1.2, -e * 0.4, -e * 2);
  tool.scale.setScalar(e / 50);
  arrowMetresPerNewton = e / 5;
  $('arrow-scale').textContent = `1 N = ${(arrowMetresPerNewton * 1e3).toFixed(0)} mm`;
}
controls.addEventListener('start', () => { controls.userMoved = true; });

// ---- messages --------------------------------------------------------------------------------
// From the view's hello: the object's own faces when it was given the scene (--scene).
const hello = { surfaceQuads: null, nodesPerAxis: 0 };
const state = { frames: 0, lastTool: 0, toolPosition: null, force: null, status: null,
                deformation: null };

function onDeformation(m) {
  if (m.configuration_id !== object.configuration || !object.ids ||
      object.ids.length !== m.node_ids.length) {
    buildObject(m);
  } else if (!state.deformation || state.deformation.primary_size !== m.primary_size ||
             state.deformation.contact_node.join() !== m.contact_node.join()) {
    colourRegions(m);
  }
  displace(m.displacement_m);
  state.deformation = m;
  state.frames += 1;
  document.body.dataset.frames = String(state.frames);
  document.body.dataset.inContact = String(m.in_contact);
  $('surface').textContent = `frame ${m.frame}, ${m.node_ids.length} nodes, ` +
      `${shown(m.latency_ms, 1)}\u00a0ms to send` +
      (m.complete ? '' : state.status?.asleep ? ', at rest' : ', a region did not step in time') +
      (object.undrawnNodes > 0 ? `; ${object.undrawnNodes} nodes on no face drawn: an object ` +
        'that leaves voxels empty? start hapticsim view with --scene (the daemon\'s scene)' : '');
}

const shown = (v, digits) => (Number.isFinite(v) ? v.toFixed(digits) : '–');

function onForce(m) {
  if (!m.force_n.every(Number.isFinite)) m.force_n = [0, 0, 0];  // drawn as none; the daemon flags it
  state.force = m;
  const [fx, fy, fz] = m.force_n, magnitude = Math.hypot(fx, fy, fz);
  $('force').textContent = `${magnitude.toFixed(3)}\u00a0N (${fx.toFixed(2)}, ${fy.toFixed(2)}, ` +
      `${fz.toFixed(2)})` + (m.in_contact ? '' : ', no contact');
}

function onStatus(m) {
  state.status = m;
  const error = Number.isFinite(m.error_percent) ? m.error_percent : -1;
  const target = Number.isFinite(m.error_target_percent) ? m.error_target_percent : 0;
  $('error').textContent = error < 0 ? 'no error map loaded'
      : `${error.toFixed(2)}\u00a0% (target ${target.toFixed(1)}\u00a0%, JND\u00a0${JND_PERCENT}\u00a0%)`;
  const full = Math.max(2 * JND_PERCENT, target * 1.2, error * 1.1);
  const bar = $('error-bar');
  bar.querySelector('.fill').style.width = `${Math.max(0, error) / full * 100}%`;
  bar.querySelector('.fill').classList.toggle('over', error > target);
  bar.querySelector('.target').style.left = `${target / full * 100}%`;
  bar.querySelector('.jnd').style.left = `${JND_PERCENT / full * 100}%`;
  $('configuration').textContent = `primary ±${m.primary_size} nodes, secondary ` +
      `${m.secondary_lod}× coarser at ${shown(m.secondary_rate_hz, 0)}\u00a0Hz` +
      (m.asleep ? ', asleep' : '') + (m.fault_latched ? ', FAULT LATCHED' : '');
  $('regions').textContent = m.regions.map((r) =>
      `${r.name} ${shown(r.rate_hz, 0)}\u00a0Hz, ${r.nodes} nodes, ${r.deadline_misses} periods late`).join('; ');
}

function onTool(m) {
  if (!m.position_m.every(Number.isFinite)) return;
  state.toolPosition = m.position_m;
  state.lastTool = performance.now();
}

// The tool tip: the device's position when the device speaks LCM; when it speaks shared memory
// only (its input is not on the bus), the touched node while in contact.
function toolTip() {
  if (state.toolPosition && performance.now() - state.lastTool < 1000) {
    return new THREE.Vector3(...state.toolPosition);
  }
  const d = state.deformation;
  if (d && d.in_contact && object.contactIndex >= 0) {
    return new THREE.Vector3().fromBufferAttribute(object.nodes, object.contactIndex);
  }
  return null;
}

function connect() {
  const socket = new WebSocket(`ws://${location.host}/feed`);
  const connection = $('connection');
  let heard = false;
  socket.onmessage = (event) => {
    const m = JSON.parse(event.data);
    if (m.type === 'hello') {
      hello.surfaceQuads = m.surface_quads ?? null;
      hello.nodesPerAxis = m.nodes_per_axis ?? 0;
      object.configuration = -1;  // (re)built with the faces this view has
      connection.className = 'waiting';
      connection.textContent = `waiting for hapticsimd on ${m.lcm_url}…`;
      return;
    }
    if (!heard) {
      heard = true;
      connection.className = 'ok';
      connection.textContent = 'live from hapticsimd';
    }
    ({ deformation: onDeformation, force: onForce, status: onStatus, tool: onTool })[m.type]?.(m);
  };
  socket.onclose = () => {
    connection.className = 'lost';
    connection.textContent = 'hapticsim view stopped: retrying every second…';
    setTimeout(connect, 1000);
  };
}
connect();

// ---- drawing -------------------------------------------------------------------------------------
let toolShown = true, framesDrawn = 0;

function render() {
  const tip = toolShown ? toolTip() : null;
  tool.visible = tip !== null;
  if (tip) tool.position.copy(tip);
  const f = state.force;
  const magnitude = f ? Math.hypot(...f.force_n) : 0;
  arrow.visible = tip !== null && magnitude > 1e-3;
  if (arrow.visible) pointArrow(tip, new THREE.Vector3(...f.force_n), arrowMetresPerNewton, object.edge / 250);
  controls.update();
  renderer.render(scene, camera);
  framesDrawn += 1;
}
renderer.setAnimationLoop(render);

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

// For tests and scripts: where the tool tip is on the screen (CSS pixels), or null.
window.hapticsimView = {
  state,
  toolOnScreen() {
    const tip = toolTip();
    if (!tip) return null;
    const p = tip.clone().project(camera);
    return { x: (p.x + 1) / 2 * window.innerWidth, y: (1 - p.y) / 2 * window.innerHeight };
  },
  // Hides or shows the tool and the arrow (the test looks at the surface alone).
  showTool(visible) { toolShown = visible; },
  // Frames drawn since the page loaded: a test waits for the next ones after a change.
  framesDrawn() { return framesDrawn; },
  // The primary region's extent the page draws, in lattice indices: {lo: [3], hi: [3]}.
  primaryExtent() { return object.primary ?? null; },
  // Where the surface mesh (the triangles drawn, not the lattice lines) has the touched node: the
  // vertices of its squares, each as [x, y, z] in m.
  surfaceAtTouchedNode() {
    if (!object.surface || object.contactIndex < 0) return [];
    const p = object.surface.geometry.attributes.position.array, out = [];
    for (let q = 0; q < object.quads.length; q += 4) {
      QUAD_TRIANGLES.forEach((corner, v) => {
        if (object.quads[q + corner] === object.contactIndex) {
          const i = 3 * ((q / 4) * 6 + v);
          out.push([p[i], p[i + 1], p[i + 2]]);
        }
      });
    }
    return out;
  },
  // The squares drawn (each four node ids) and the surface nodes on none of them.
  surfaceDrawn() {
    const quads = [];
    for (const v of object.quads ?? []) quads.push(object.ids[v]);
    return { quads, undrawnNodes: object.undrawnNodes ?? 0, nodeIds: object.ids ?? [] };
  },
  // The touched node where the page draws it now (object frame, m), or null.
  touchedNodeDrawn() {
    if (!object.nodes || object.contactIndex < 0) return null;
    return new THREE.Vector3().fromBufferAttribute(object.nodes, object.contactIndex).toArray();
  },
};
