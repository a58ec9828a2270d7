// The Obscura camera explorer page: controls generated from CONTROLS, frames over a WebSocket,
// drag to orbit, click to focus, coordinates overlay, post-process comparison, saves.
'use strict';

const PROJECTIVE = ['perspective', 'orthographic'];
const OPENCV = ['opencv', 'opencv_fisheye'];

// One entry per [camera] key (docs/scene-format.md); a key of a sub-table is dotted
// (`stereo.interaxial` is [camera.stereo] interaxial). `models` lists the camera types the key
// applies to (absent: all). `pose` names the way of giving the pose a key belongs to: a
// look-at, OpenCV extrinsics or a matrix, one way at a time. A new camera model is one entry
// in /api/scene's types plus entries here for its own keys.
const CONTROLS = [
  { key: 'type', kind: 'select', options: [] /* from /api/scene */ },
  { key: 'fov', kind: 'range', min: 1, max: 179, step: 0.5, def: 90,
    models: ['perspective', 'fisheye', 'cylindrical'] },
  { key: 'fov_axis', kind: 'select', options: ['smaller', 'larger', 'x', 'y', 'diagonal'],
    def: 'smaller', models: ['perspective'] },
  { key: 'screen_window', kind: 'vec', n: 4, optional: true, placeholder: '(from the fov)',
    models: PROJECTIVE },
  { key: 'eye', kind: 'vec', n: 3, def: [0, 0, 0], pose: 'look-at' },
  { key: 'target', kind: 'vec', n: 3, def: [0, 0, -1], pose: 'look-at' },
  { key: 'up', kind: 'vec', n: 3, def: [0, 1, 0], pose: 'look-at' },
  { key: 'lens_radius', kind: 'range', min: 0, max: 1, step: 0.005, def: 0, models: PROJECTIVE },
  { key: 'focal_distance', kind: 'range', min: 0.05, max: 50, step: 0.01, def: 1,
    models: PROJECTIVE },
  { key: 'aperture_blades', kind: 'int', min: 0, max: 64, def: 0,
    models: [...PROJECTIVE, 'realistic'] },
  { key: 'aperture_rotation', kind: 'range', min: 0, max: 360, step: 1, def: 0,
    models: [...PROJECTIVE, 'realistic'] },
  { key: 'shutter', kind: 'vec', n: 2, def: [0, 1] },
  { key: 'eye_end', kind: 'vec', n: 3, optional: true, pose: 'look-at' },
  { key: 'target_end', kind: 'vec', n: 3, optional: true, pose: 'look-at' },
  { key: 'up_end', kind: 'vec', n: 3, optional: true, pose: 'look-at' },
  // Shown `exact`: an edit elsewhere in the field must not round an imported pose.
  { key: 'rvec', kind: 'vec', n: 3, optional: true, pose: 'extrinsics', exact: true },
  { key: 'tvec', kind: 'vec', n: 3, optional: true, pose: 'extrinsics', exact: true },
  { key: 'pose', kind: 'vec', n: 16, optional: true, pose: 'matrix', exact: true,
    placeholder: '16 numbers, row-major' },
  { key: 'pose_end', kind: 'vec', n: 16, optional: true, pose: 'matrix', exact: true,
    placeholder: '16 numbers, row-major' },
  { key: 'near', kind: 'number', def: 0.001 },
  { key: 'far', kind: 'number', def: 1e30 },
  { key: 'lens_shift', kind: 'vec', n: 2, def: [0, 0],
    models: ['perspective', 'orthographic', 'fisheye'] },
  { key: 'projection', kind: 'select',
    options: ['equidistant', 'equisolid', 'stereographic', 'orthographic'], def: 'equidistant',
    models: ['fisheye'] },
  { key: 'face', kind: 'select', options: ['+x', '-x', '+y', '-y', '+z', '-z'], def: '+z',
    models: ['cube_face'] },
  { key: 'fx', kind: 'number', models: OPENCV },
  { key: 'fy', kind: 'number', models: OPENCV },
  { key: 'cx', kind: 'number', models: OPENCV },
  { key: 'cy', kind: 'number', models: OPENCV },
  { key: 'distortion', kind: 'list', models: OPENCV },
  { key: 'aperture_image', kind: 'text', optional: true, models: [...PROJECTIVE, 'realistic'] },
  { key: 'anamorphic', kind: 'number', def: 1, models: [...PROJECTIVE, 'realistic'] },
  { key: 'focal_plane_tilt', kind: 'vec', n: 2, def: [0, 0], models: ['perspective', 'orthographic', 'realistic'] },
  { key: 'focal_length', kind: 'number', optional: true, models: PROJECTIVE },
  { key: 'shutter_curve', kind: 'json', optional: true, placeholder: '[[0, 0], [0.5, 1], [1, 0]]' },
  { key: 'rolling_shutter', kind: 'json', optional: true,
    placeholder: '{"readout": 0.5, "direction": "top_to_bottom"}' },
  { key: 'f_number', kind: 'number', optional: true },
  { key: 'shutter_time', kind: 'number', optional: true },
  { key: 'iso', kind: 'number', optional: true },
  { key: 'exposure_compensation', kind: 'number', optional: true },
  { key: 'lens_file', kind: 'text', models: ['realistic'] },
  { key: 'aperture_diameter', kind: 'number', optional: true, models: ['realistic'] },
  { key: 'focus_distance', kind: 'number', def: 10, models: ['realistic'] },
  { key: 'film_diagonal', kind: 'number', def: 35, models: ['realistic'] },
  { key: 'stereo.interaxial', kind: 'number', optional: true, placeholder: '0.065',
    models: ['perspective', 'ods'] },
  { key: 'stereo.convergence', kind: 'number', optional: true, models: ['perspective'] },
  { key: 'stereo.layout', kind: 'select', options: ['side_by_side', 'separate', 'anaglyph'],
    def: 'side_by_side', optional: true, models: ['perspective'] },
];

// The ways of giving the pose: the keys that always go together, and what the others' fields
// say while one is in use.
const POSE_PAIRS = { extrinsics: ['rvec', 'tvec'], matrix: ['pose'] };
const POSE_NAMES = { 'look-at': 'eye, target, up', extrinsics: 'rvec, tvec', matrix: 'pose' };

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const ctx = canvas.getContext('2d', { willReadFrequently: true });

// What the page knows; window.explorer lets tests read it.
const state = {
  session: null, camera: {}, resolution: [1, 1], spp: 1, generation: 0,
  frame: { generation: -1, pass: 0, passes: 0 }, effective: {}, clamped: [], stereo: null,
  lastError: null,
};
window.explorer = state;

let socket = null;

function applies(control, type) {
  return !control.models || control.models.includes(type);
}

function currentType() {
  return state.camera.type || 'perspective';
}

// The [camera] key a control's key lives under (`stereo` for `stereo.interaxial`).
function topKey(key) {
  return key.split('.')[0];
}

// The element id of a control's input.
function idOf(key) {
  return 'c-' + key.replace('.', '-');
}

// The value of a (dotted) key in the view's [camera] table, or undefined.
function cameraValue(key) {
  const [top, sub] = key.split('.');
  const v = state.camera[top];
  if (sub === undefined) return v;
  return v && typeof v === 'object' ? v[sub] : undefined;
}

function valueOf(key) {
  const v = cameraValue(key);
  if (v !== undefined) return v;
  if (key in state.effective) return state.effective[key];
  const c = CONTROLS.find((c) => c.key === key);
  return c ? c.def : undefined;
}

// How the view gives its pose: 'look-at' unless it has extrinsics or a matrix.
function activePose() {
  const c = CONTROLS.find((c) => c.pose && c.pose !== 'look-at' && c.key in state.camera);
  return c ? c.pose : 'look-at';
}

function send(change) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(change));
}

function setCamera(key, value) {
  const change = { camera: {} };
  const [top, sub] = key.split('.');
  if (sub === undefined) {
    change.camera[key] = value;
  } else {
    // A key of a sub-table: the whole table goes, with this key changed (none left: removed).
    const table = { ...(state.camera[top] || {}) };
    if (value === null) delete table[sub];
    else table[sub] = value;
    change.camera[top] = Object.keys(table).length ? table : null;
  }
  if (key === 'type') {
    // Drop the keys (and tables) the new model does not take.
    const kept = new Set(CONTROLS.filter((c) => applies(c, value)).map((c) => topKey(c.key)));
    for (const c of CONTROLS) {
      const t = topKey(c.key);
      if (t in state.camera && !kept.has(t)) change.camera[t] = null;
    }
  }
  const pose = (CONTROLS.find((c) => c.key === key) || {}).pose;
  if (pose && value !== null) {
    // One way of giving the pose at a time: the others' keys go.
    for (const c of CONTROLS) {
      if (c.pose && c.pose !== pose && c.key in state.camera) change.camera[c.key] = null;
    }
    // Extrinsics come in pairs: the other at its value, else zero.
    for (const k of pose === 'extrinsics' ? POSE_PAIRS.extrinsics : []) {
      if (!(k in change.camera)) change.camera[k] = state.camera[k] || [0, 0, 0];
    }
  } else if (pose && value === null && POSE_PAIRS[pose] && POSE_PAIRS[pose].includes(key)) {
    // Without its partner (rvec, tvec) or its start (pose), the rest cannot stay.
    for (const c of CONTROLS) if (c.pose === pose && c.key in state.camera) change.camera[c.key] = null;
  }
  send(change);
}

function buildControls(types) {
  const form = $('controls');
  form.textContent = '';
  CONTROLS[0].options = types;
  const legend = document.createElement('legend');
  const fs = document.createElement('fieldset');
  legend.textContent = 'Camera';
  fs.append(legend);
  for (const c of CONTROLS) {
    const label = document.createElement('label');
    label.dataset.key = c.key;
    const name = document.createElement('span');
    name.className = 'key';
    name.textContent = c.key;
    label.append(name);
    if (c.kind === 'select') {
      const sel = document.createElement('select');
      sel.id = idOf(c.key);
      // An optional key's empty choice removes it (the format's default applies).
      if (c.optional) sel.append(new Option(`(default: ${c.def})`, ''));
      for (const o of c.options) sel.append(new Option(o, o));
      sel.addEventListener('change', () => setCamera(c.key, c.optional && sel.value === '' ? null : sel.value));
      label.append(sel);
    } else if (c.kind === 'range') {
      const input = document.createElement('input');
      Object.assign(input, { type: 'range', min: c.min, max: c.max, step: c.step, id: idOf(c.key) });
      const out = document.createElement('output');
      input.addEventListener('input', () => {
        out.textContent = input.value;
        setCamera(c.key, Number(input.value));
      });
      label.append(input, out);
    } else if (c.kind === 'int' || c.kind === 'number') {
      const input = document.createElement('input');
      Object.assign(input, { type: 'number', id: idOf(c.key), step: c.kind === 'int' ? 1 : 'any',
        placeholder: c.placeholder || (c.optional ? '(none)' : '') });
      input.addEventListener('change', () => {
        if (input.value.trim() === '' && c.optional) return setCamera(c.key, null);
        setCamera(c.key, Number(input.value));
      });
      label.append(input);
    } else if (c.kind === 'vec' || c.kind === 'list') {
      const input = document.createElement('input');
      Object.assign(input, { type: 'text', id: idOf(c.key), size: 16,
        placeholder: c.placeholder || (c.optional ? '(none)' : '') });
      input.addEventListener('change', () => {
        const text = input.value.trim();
        if (text === '' && (c.optional || c.kind === 'list')) return setCamera(c.key, null);
        const v = text.split(/[\s,]+/).map(Number);
        if (c.kind === 'vec' && v.length !== c.n) return showError(`${c.key}: ${c.n} numbers, please`);
        setCamera(c.key, v);
      });
      label.append(input);
    } else if (c.kind === 'text' || c.kind === 'json') {
      // A string (a file name, relative to the scene file) or a value written as JSON (a
      // curve of [t, openness] pairs, a table).
      const input = document.createElement('input');
      Object.assign(input, { type: 'text', id: idOf(c.key), size: 16,
        placeholder: c.placeholder || (c.optional ? '(none)' : '') });
      input.addEventListener('change', () => {
        const text = input.value.trim();
        if (text === '' && c.optional) return setCamera(c.key, null);
        if (c.kind === 'text') return setCamera(c.key, text);
        let v;
        try { v = JSON.parse(text); } catch (e) { return showError(`${c.key}: ${e.message}`); }
        setCamera(c.key, v);
      });
      label.append(input);
    }
    fs.append(label);
  }
  form.append(fs);
}

function fmt(v) {
  return typeof v === 'number' ? String(Math.round(v * 1e4) / 1e4) : String(v);
}

function showControls() {
  const type = currentType();
  const pose = activePose();
  for (const c of CONTROLS) {
    const label = document.querySelector(`label[data-key="${c.key}"]`);
    if (!label) continue;
    label.classList.toggle('hidden', !applies(c, type));
    const input = $(idOf(c.key));
    if (document.activeElement === input && c.kind !== 'range') continue;
    // The keys of another way of giving the pose show empty while this one is in use.
    const unused = c.pose && c.pose !== pose;
    if (c.pose) {
      input.placeholder = unused ? `(pose from ${POSE_NAMES[pose]})` : c.placeholder || (c.optional ? '(none)' : '');
    }
    // An optional choice shows empty (its default) while the view does not give it.
    const v = unused ? undefined : c.kind === 'select' && c.optional ? cameraValue(c.key) ?? '' : valueOf(c.key);
    if (c.kind === 'vec' || c.kind === 'list') input.value = v === undefined ? '' : v.map(c.exact ? String : fmt).join(', ');
    else if (c.kind === 'json') input.value = v === undefined ? '' : JSON.stringify(v);
    else if (v !== undefined) input.value = v;
    else if (c.kind !== 'select' && c.kind !== 'range') input.value = '';
    if (c.kind === 'range') label.querySelector('output').textContent = fmt(Number(input.value));
  }
  $('res-w').value = state.resolution[0];
  $('res-h').value = state.resolution[1];
  $('spp').value = state.spp;
  const q = `?session=${state.session}`;
  $('save-toml').href = '/api/scene.toml' + q;
  // A `separate` stereo pair saves one file per eye, as `obscura render` writes it.
  const separate = !!state.stereo && state.stereo.layout === 'separate';
  for (const ext of ['png', 'exr']) {
    const [one, right] = [$(`save-${ext}`), $(`save-${ext}-right`)];
    one.href = `/api/image.${ext}` + q + (separate ? '&eye=left' : '');
    one.download = separate ? `view-left.${ext}` : `view.${ext}`;
    one.textContent = `${separate ? 'left image' : 'image'} (.${ext})`;
    right.href = `/api/image.${ext}` + q + '&eye=right';
    right.hidden = !separate;
  }
}

function showError(message) {
  state.lastError = message;
  $('error').textContent = message || '';
}

// What the page shows differs from what the scene file asks for: the settings previewed at
// the explorer's limits, and a `separate` stereo pair shown side by side in the one image.
function showNotices() {
  const notes = state.clamped.map((c) => c.message);
  if (state.stereo && state.stereo.layout === 'separate') {
    notes.push('camera.stereo.layout = separate: the preview shows the left and right eyes ' +
      'side by side; `obscura render` writes them as NAME-left and NAME-right, and the image ' +
      'saves one file per eye');
  }
  $('notice').textContent = notes.join(' · ');
}

function takeView(msg) {
  state.camera = msg.camera || {};
  state.resolution = msg.resolution;
  state.spp = msg.spp;
  state.clamped = msg.clamped || [];
  state.stereo = msg.stereo || null;
  state.effective = msg.effective || {};
  if (msg.generation !== undefined) state.generation = msg.generation;
  showError(null);
  showControls();
  showNotices();
  scheduleCompare();
}

// Frames decode concurrently; only the latest received is drawn, so a frame that finishes
// decoding after a later one cannot put an older pass back on the canvas.
let framesReceived = 0;
async function onFrame(buffer) {
  const seq = ++framesReceived;
  const head = new DataView(buffer, 0, 12);
  const generation = head.getUint32(0, true);
  const pass = head.getUint32(4, true);
  const passes = head.getUint32(8, true);
  const bitmap = await createImageBitmap(new Blob([buffer.slice(12)], { type: 'image/png' }));
  if (seq !== framesReceived) {
    bitmap.close();
    return;
  }
  if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
    canvas.width = bitmap.width;
    canvas.height = bitmap.height;
  }
  ctx.drawImage(bitmap, 0, 0);
  state.frame = { generation, pass, passes };
  canvas.dataset.generation = generation;
  canvas.dataset.pass = pass;
  $('progress').textContent = `pass ${pass} / ${passes}`;
}

function connect() {
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  socket = new WebSocket(`${proto}//${location.host}/api/ws`);
  socket.binaryType = 'arraybuffer';
  socket.onmessage = (e) => {
    if (typeof e.data !== 'string') return onFrame(e.data);
    const msg = JSON.parse(e.data);
    if (msg.type === 'hello') {
      state.session = msg.session;
      takeView(msg);
    } else if (msg.type === 'view') {
      takeView(msg);
    } else if (msg.type === 'error') {
      showError(msg.error);
      showControls();
    }
  };
  socket.onclose = () => { $('progress').textContent = 'disconnected (reload to reconnect)'; };
}

// Raster position of a pointer event.
function rasterOf(e) {
  const r = canvas.getBoundingClientRect();
  return [(e.clientX - r.left) / r.width * canvas.width, (e.clientY - r.top) / r.height * canvas.height];
}

// Drag orbits the eye about the target (turntable about world +y); a click without a drag
// focuses on the surface under the pointer.
let drag = null;
canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.clientX, y: e.clientY, moved: false, eye: valueOf('eye'), target: valueOf('target') };
  canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointermove', (e) => {
  hover(e);
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  if (!drag.moved && Math.hypot(dx, dy) < 4) return;
  drag.moved = true;
  if (activePose() !== 'look-at') {
    return showError(`orbit: the pose comes from ${POSE_NAMES[activePose()]}; dragging orbits a look-at (eye, target)`);
  }
  const [ex, ey, ez] = drag.eye, [tx, ty, tz] = drag.target;
  const v = [ex - tx, ey - ty, ez - tz];
  const r = Math.hypot(...v);
  if (r === 0) return;
  let az = Math.atan2(v[0], v[2]) - dx * 0.01;
  let el = Math.asin(Math.max(-1, Math.min(1, v[1] / r))) + dy * 0.01;
  el = Math.max(-1.5, Math.min(1.5, el));
  const eye = [tx + r * Math.cos(el) * Math.sin(az), ty + r * Math.sin(el), tz + r * Math.cos(el) * Math.cos(az)];
  setCamera('eye', eye);
});
canvas.addEventListener('pointerup', async (e) => {
  const wasDrag = drag && drag.moved;
  drag = null;
  if (wasDrag) return;
  const [x, y] = rasterOf(e);
  const res = await fetch(`/api/focus?session=${state.session}`, {
    method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ x, y }),
  });
  const body = await res.json();
  if (!res.ok) return showError(body.error);
  state.focus = { x, y, depth: body.depth };
  takeView(body);
});
canvas.addEventListener('pointerleave', () => { $('overlay').textContent = ''; });

// The coordinates overlay, asked of the camera crate (one request at a time).
let hoverBusy = false, hoverNext = null;
async function hover(e) {
  hoverNext = rasterOf(e);
  if (hoverBusy) return;
  hoverBusy = true;
  while (hoverNext) {
    const [x, y] = hoverNext;
    hoverNext = null;
    try {
      const res = await fetch(`/api/coords?session=${state.session}&x=${x}&y=${y}`);
      const c = await res.json();
      const v3 = (a) => a.map((n) => n.toFixed(3).padStart(8)).join(' ');
      // A stereo pair's image: the coordinates are on the film of the eye under the pointer
      // (an anaglyph's, the rig centre's).
      let text = c.eye ? `eye    ${c.eye}\n` : '';
      text += `raster ${v3(c.raster)}\n`;
      if (c.projective) {
        const p = c.projective;
        text += `NDC    ${v3(p.ndc)}\nscreen ${v3(p.screen)}\ncamera ${v3(p.camera)}  (on the near plane)\n`;
        // A perspective camera's near plane is tiny: the same direction on the plane z = 1.
        if (currentType() === 'perspective' && p.camera[2] > 0) {
          text += `       ${v3(p.camera.map((v) => v / p.camera[2]))}  (on z = 1)\n`;
        }
      }
      if (c.ray) text += `ray d  ${v3(c.ray.direction)}`;
      else text += 'no ray leaves this pixel';
      $('overlay').textContent = text;
    } catch (err) { /* the next move asks again */ }
  }
  hoverBusy = false;
}

// The post-process comparison, refreshed a moment after the view settles.
let compareTimer = null;
function scheduleCompare() {
  clearTimeout(compareTimer);
  compareTimer = setTimeout(refreshCompare, 400);
}
let compareAsked = 0;
async function refreshCompare() {
  const mode = $('compare-mode').value;
  $('compare').hidden = !mode;
  $('stage').classList.toggle('comparing', !!mode);
  if (!mode || state.session === null) return;
  // Answers may come back out of order: only the latest request's is shown.
  const asked = ++compareAsked;
  $('post-caption').textContent = 'post-process: rendering…';
  const res = await fetch(`/api/postprocess.png?session=${state.session}&effect=${mode}`);
  if (asked !== compareAsked) return;
  if (!res.ok) {
    const body = await res.json();
    $('post-caption').textContent = body.error;
    $('post').removeAttribute('src');
    return;
  }
  const blob = await res.blob();
  if (asked !== compareAsked) return;
  if ($('post').src) URL.revokeObjectURL($('post').src);
  $('post').src = URL.createObjectURL(blob);
  $('post-caption').textContent = mode === 'dof'
    ? 'post-process depth of field (Potmesil and Chakravarty) of a pinhole image'
    : 'post-process motion blur (Potmesil and Chakravarty) of an instant';
}
$('compare-mode').addEventListener('change', refreshCompare);

$('res-w').addEventListener('change', () => send({ resolution: [Number($('res-w').value), Number($('res-h').value)] }));
$('res-h').addEventListener('change', () => send({ resolution: [Number($('res-w').value), Number($('res-h').value)] }));
$('spp').addEventListener('change', () => send({ spp: Number($('spp').value) }));

fetch('/api/scene').then((r) => r.json()).then((scene) => {
  $('file').textContent = scene.file;
  buildControls(scene.types);
  connect();
});
