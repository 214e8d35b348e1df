// The fitting room: make a body, pick a garment and a size, watch it being dressed, and see the fit
// in 3D and in words. Talks to drape serve's JSON API (docs/web.md); three.js is served by drape
// from the npm package.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';

const $ = (id) => document.getElementById(id);
const SKIN = 0xe2baa0;
const DEFAULTS = {
  female: { height: 165, bust: 92, waist: 74, hips: 98 },
  male: { height: 178, bust: 98, waist: 84, hips: 98 },
};

const state = {
  garments: [], garment: null, size: null, body: null, bodyRequest: null,
  tryon: null, dressed: null, fit: null, showFit: false, polling: 0,
};

// ---- Talking to the server ---------------------------------------------------------------------

class ApiError extends Error {
  constructor(message, status, retryAfter) { super(message); this.status = status; this.retryAfter = retryAfter; }
}

async function api(path, options = {}) {
  let response;
  try {
    response = await fetch(path, options);
  } catch {
    throw new ApiError('The fitting room cannot be reached. Check your connection and try again.', 0);
  }
  if (response.status === 204) return null;
  let data = null;
  try { data = await response.json(); } catch { /* not JSON: described below */ }
  if (!response.ok) {
    const message = (data && data.error) || `The server answered ${response.status}.`;
    throw new ApiError(plainWords(message, response.status), response.status,
                       Number(response.headers.get('Retry-After')) || 0);
  }
  return { status: response.status, data };
}

// Server messages name the field or file; say what the shopper can do about it.
function plainWords(message, status) {
  if (status === 413) return `That file is too large for the fitting room (${message}). Try a smaller or simplified scan.`;
  if (message.startsWith('upload.')) return `We could not read your scan: ${message.replace(/^upload\.\w+: /, '')}.`;
  if (message.startsWith('measurements:')) return `Please check your measurements: ${message.replace(/^measurements: /, '')}.`;
  return message.charAt(0).toUpperCase() + message.slice(1);
}

function showError(message) {
  const box = $('error');
  box.textContent = message;
  box.hidden = !message;
}

// ---- 3D view -------------------------------------------------------------------------------------

const canvas = $('canvas');
// preserveDrawingBuffer: the picture can be read back (copied, checked) after it is drawn.
// alpha: the page's backdrop shows behind the body.
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, alpha: true, preserveDrawingBuffer: true });
renderer.setClearColor(0x000000, 0);
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
const scene = new THREE.Scene();
scene.environment = new THREE.PMREMGenerator(renderer).fromScene(new RoomEnvironment(), 0.04).texture;
scene.environmentIntensity = 0.55;
const key = new THREE.DirectionalLight(0xffffff, 0.9);
key.position.set(1.5, 3, 2.5);
scene.add(key);
const camera = new THREE.PerspectiveCamera(30, 1, 0.05, 50);
camera.position.set(0, 1.0, 3.7);
const controls = new OrbitControls(camera, canvas);
controls.target.set(0, 0.9, 0);
controls.enableDamping = true;
controls.minDistance = 1.2;
controls.maxDistance = 8;
controls.update();
const floor = new THREE.Mesh(new THREE.CircleGeometry(0.7, 64),
                             new THREE.MeshStandardMaterial({ color: 0xb9b2a8, roughness: 1 }));
floor.rotation.x = -Math.PI / 2;
scene.add(floor);
let shown = null;

// Drawn only when something changed (the camera moved, a model came, the view resized): an idle
// fitting room costs the shopper's computer nothing.
let redraw = true;
const requestRedraw = () => { redraw = true; };

function resize() {
  const { clientWidth: w, clientHeight: h } = $('viewer');
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  redraw = true;
}
new ResizeObserver(resize).observe($('viewer'));
resize();
renderer.setAnimationLoop(() => {
  if (controls.update()) redraw = true;
  if (!redraw) return;
  redraw = false;
  renderer.render(scene, camera);
  // What the canvas now shows: a page that reads the picture back (tests, screenshots) waits for
  // this rather than for a time, which a slow software renderer can overrun.
  document.body.dataset.drawn = document.body.dataset.view || '';
});

// Keyboard: arrows turn the body, +/- zoom, when the view has focus.
$('viewer').addEventListener('keydown', (e) => {
  const turn = { ArrowLeft: -0.15, ArrowRight: 0.15 }[e.key];
  if (turn) { camera.position.applyAxisAngle(new THREE.Vector3(0, 1, 0), turn); requestRedraw(); e.preventDefault(); }
  if (e.key === '+' || e.key === '-') {
    camera.position.lerp(controls.target, e.key === '+' ? 0.1 : -0.1);
    requestRedraw();
    e.preventDefault();
  }
});

const loader = new GLTFLoader();
function loadGlb(url) {
  return new Promise((resolve, reject) => loader.load(url, (g) => resolve(g.scene), undefined,
    () => reject(new ApiError('The 3D model could not be loaded. Please try again.', 0))));
}

// Materials: the body in skin, garments in their fabric's colour; or, for the fit map, the
// vertex colours drape computed (strain on the cloth, pressure on the skin).
function dress(root, fitMap) {
  root.traverse((o) => {
    if (!o.isMesh) return;
    const isBody = o.name === 'body' || (o.parent && o.parent.name === 'body') || o.isSkinnedMesh;
    const colour = isBody ? SKIN : new THREE.Color(state.garment ? state.garment.colour : '#3a5e8c');
    o.material = fitMap && o.geometry.getAttribute('color')
      ? new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.85, side: THREE.DoubleSide })
      : new THREE.MeshStandardMaterial({ color: colour, roughness: isBody ? 0.6 : 0.9, metalness: 0,
                                         side: THREE.DoubleSide });
  });
  return root;
}

function show(root, label) {
  if (shown) scene.remove(shown);
  shown = root;
  if (root) scene.add(root);
  $('empty').hidden = !!root;
  requestRedraw();
  document.body.dataset.view = label;
  delete document.body.dataset.drawn;
}

// ---- Body ----------------------------------------------------------------------------------------

function measureForm() { return $('measure-form'); }
function sex() { return measureForm().elements.sex.value; }
function setDefaults(which) {
  for (const [k, v] of Object.entries(DEFAULTS[which])) measureForm().elements[k].value = v;
  document.querySelectorAll('[data-female]').forEach((e) => { e.hidden = which !== 'female'; });
  document.querySelectorAll('[data-male]').forEach((e) => { e.hidden = which !== 'male'; });
}

function measurementsFromForm() {
  const out = {};
  for (const k of ['height', 'bust', 'waist', 'hips']) {
    const input = measureForm().elements[k];
    const cm = Number(input.value);
    const label = k === 'bust' && sex() === 'male' ? 'chest' : k;
    if (!input.value || !Number.isFinite(cm)) throw new ApiError(`Please enter your ${label} in centimetres.`, 400);
    if (cm < Number(input.min) || cm > Number(input.max))
      throw new ApiError(`Your ${label} of ${cm} cm is outside ${input.min}-${input.max} cm: please check it.`, 400);
    out[k] = Math.round(cm * 10) / 1000;
  }
  return out;
}

async function makeBody(request, upload) {
  showError('');
  const button = upload ? $('upload-body') : $('make-body');
  button.disabled = true;
  button.textContent = upload ? 'Reading your scan…' : 'Making your body…';
  try {
    const { data } = upload
      ? await api('/api/bodies', { method: 'POST', body: upload })
      : await api('/api/bodies', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                   body: JSON.stringify(request) });
    // The shopper's previous body is deleted once the new one exists (a refused upload keeps it).
    if (state.body) api(`/api/bodies/${state.body.id}`, { method: 'DELETE' }).catch(() => {});
    state.body = data;
    state.bodyRequest = upload ? null : request;
    state.tryon = null; state.dressed = null; state.fit = null;
    setFitMap(false);
    const m = data.measurements;
    $('body-text').textContent = `Height ${(data.height_m * 100).toFixed(0)} cm · bust ${(m.bust * 100).toFixed(0)} cm · ` +
      `waist ${(m.waist * 100).toFixed(0)} cm · hips ${(m.hips * 100).toFixed(0)} cm, as measured on your body.`;
    $('body-summary').hidden = false;
    show(dress(await loadGlb(`/api/bodies/${data.id}/body.glb`), false), 'body');
    $('verdict').hidden = true;
    updateButtons();
  } catch (e) {
    showError(e.message);
  } finally {
    button.disabled = false;
    button.textContent = upload ? 'Upload my scan' : 'Make my body';
  }
}

$('measure-form').addEventListener('submit', (e) => {
  e.preventDefault();
  try {
    makeBody({ sex: sex(), measurements: measurementsFromForm() });
  } catch (err) { showError(err.message); }
});
measureForm().elements.sex.forEach((r) => r.addEventListener('change', () => setDefaults(sex())));

$('upload-form').addEventListener('submit', (e) => {
  e.preventDefault();
  const form = $('upload-form');
  if (!form.elements.file.files.length) { showError('Please choose a body scan to upload (OBJ, PLY or GLB).'); return; }
  makeBody(null, new FormData(form));
});

// Tabs: measurements or upload (arrow keys move between them).
const tabs = [$('tab-measure'), $('tab-upload')];
function selectTab(tab) {
  for (const t of tabs) {
    const on = t === tab;
    t.setAttribute('aria-selected', String(on));
    t.tabIndex = on ? 0 : -1;
    $(t.getAttribute('aria-controls')).hidden = !on;
  }
  tab.focus();
}
tabs.forEach((t, i) => {
  t.addEventListener('click', () => selectTab(t));
  t.addEventListener('keydown', (e) => {
    if (e.key === 'ArrowRight' || e.key === 'ArrowLeft') selectTab(tabs[(i + 1) % 2]);
  });
});

$('delete-body').addEventListener('click', async () => {
  if (!state.body) return;
  try {
    await api(`/api/bodies/${state.body.id}`, { method: 'DELETE' });
  } catch (e) { if (e.status !== 404) { showError(e.message); return; } }
  state.body = null; state.tryon = null; state.dressed = null; state.fit = null;
  $('body-summary').hidden = true;
  $('verdict').hidden = true;
  setFitMap(false);
  show(null, 'empty');
  updateButtons();
});

// ---- Catalogue and sizes -------------------------------------------------------------------------

function radioKeys(container, selector) {
  container.addEventListener('keydown', (e) => {
    const items = [...container.querySelectorAll(selector)];
    const at = items.indexOf(document.activeElement);
    if (at < 0) return;
    const step = { ArrowRight: 1, ArrowDown: 1, ArrowLeft: -1, ArrowUp: -1 }[e.key];
    if (!step) return;
    e.preventDefault();
    items[(at + step + items.length) % items.length].focus();
  });
}

function renderCatalogue() {
  const box = $('catalogue');
  box.replaceChildren();
  for (const g of state.garments) {
    const card = document.createElement('button');
    card.type = 'button';
    card.className = 'card';
    card.setAttribute('role', 'radio');
    card.dataset.garment = g.name;
    card.setAttribute('aria-checked', String(state.garment === g));
    const img = document.createElement('img');
    img.src = g.thumbnail;
    img.alt = `${g.name}: the pattern pieces`;
    img.loading = 'lazy';
    const name = document.createElement('span');
    name.className = 'name';
    name.textContent = g.name;
    const fabric = document.createElement('span');
    fabric.className = 'fabric';
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = g.colour;
    fabric.append(swatch, `${g.fabric} · ${g.sizes.join(' ')}`);
    card.title = g.description.split('. ')[0];
    card.append(img, name, fabric);
    card.addEventListener('click', () => selectGarment(g.name));
    box.append(card);
  }
}

function selectGarment(name, size) {
  state.garment = state.garments.find((g) => g.name === name) || null;
  if (!state.garment) return;
  state.size = size && (size === 'auto' || state.garment.sizes.includes(size)) ? size : null;
  document.querySelectorAll('.card').forEach((c) => c.setAttribute('aria-checked', String(c.dataset.garment === name)));
  const box = $('sizes');
  box.replaceChildren();
  for (const s of [...state.garment.sizes, 'auto']) {
    const b = document.createElement('button');
    b.type = 'button';
    b.setAttribute('role', 'radio');
    b.dataset.size = s;
    b.textContent = s === 'auto' ? 'Find my size' : s;
    if (s === 'auto') b.title = 'Every size is tried on your body and the best one recommended (takes longer)';
    b.setAttribute('aria-checked', String(state.size === s));
    b.addEventListener('click', () => {
      state.size = s;
      box.querySelectorAll('button').forEach((x) => x.setAttribute('aria-checked', String(x === b)));
      updateButtons();
    });
    box.append(b);
  }
  updateButtons();
}
radioKeys($('catalogue'), '.card');
radioKeys($('sizes'), 'button');

function updateButtons() {
  $('tryon').disabled = !(state.body && state.garment && state.size) || state.polling > 0;
  $('fitmap').disabled = !(state.tryon && state.tryon.state === 'done');
  $('share').disabled = !(state.bodyRequest && state.garment && state.size);
}

// ---- Try-on --------------------------------------------------------------------------------------

function setProgress(visible, fraction, text) {
  $('progress').hidden = !visible;
  $('progress-bar').style.width = `${Math.round(100 * (fraction || 0))}%`;
  $('progress-text').textContent = text || '';
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function tryOn() {
  showError('');
  $('verdict').hidden = true;
  setFitMap(false);
  state.polling += 1;
  updateButtons();
  const request = { body: state.body.id, garment: state.garment.name, size: state.size };
  try {
    let submitted;
    for (;;) {
      try {
        submitted = await api('/api/tryons', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                               body: JSON.stringify(request) });
        break;
      } catch (e) {
        if (e.status !== 503) throw e;
        const wait = Math.max(2, e.retryAfter || 5);
        setProgress(true, 0, `Every fitting room is busy: trying again in ${wait} s…`);
        await sleep(wait * 1000);
      }
    }
    const id = submitted.data.id;
    let t;
    for (;;) {
      ({ data: t } = await api(`/api/tryons/${id}`));
      if (t.state === 'done' || t.state === 'failed') break;
      const what = t.state === 'queued' ? 'Waiting for a fitting room…'
        : state.size === 'auto' ? `Trying every size on… ${Math.round(100 * t.progress)} %`
        : `${t.progress < 0.5 ? 'Sewing' : 'Draping'} your ${t.garment}… ${Math.round(100 * t.progress)} %`;
      setProgress(true, t.progress, what);
      await sleep(400);
    }
    state.tryon = t;
    if (t.state === 'failed') throw new ApiError(plainWords(t.error, 500), 500);
    setProgress(true, 1, 'Putting it on…');
    state.dressed = dress(await loadGlb(t.files.dressed), false);
    state.fit = null;
    show(state.dressed, 'dressed');
    showVerdict(t);
  } catch (e) {
    showError(e.message);
  } finally {
    setProgress(false);
    state.polling -= 1;
    updateButtons();
  }
}
$('tryon').addEventListener('click', tryOn);

const REGION = { upper_arm: 'upper arms', sleeve_length: 'sleeve length', leg_length: 'leg length',
                 garment_length: 'length', thighs: 'thighs' };
function showVerdict(t) {
  const box = $('verdict');
  box.replaceChildren();
  const report = t.report || {};
  const garmentFit = report.fit && report.fit.garments && report.fit.garments[0];
  const regions = (garmentFit && garmentFit.regions) || [];
  const tight = regions.filter((r) => r.verdict === 'tight').map((r) => REGION[r.region] || r.region);
  const h = document.createElement('h3');
  const sizeWord = t.size_requested === 'auto' ? `Your size: ${t.size}` : `Size ${t.size}`;
  h.textContent = !report.passed ? `${sizeWord} does not fit well`
    : tight.length ? `${sizeWord} is tight at the ${tight.join(' and ')}` : `${sizeWord} fits`;
  box.append(h);
  const advice = report.size_advice;
  if (advice && advice.reasons) {
    for (const line of advice.reasons) {
      const p = document.createElement('p');
      p.textContent = line;
      box.append(p);
    }
  }
  if (!report.passed && report.gates) {
    const p = document.createElement('p');
    p.textContent = (report.gates.checks || []).filter((c) => !c.passed).map((c) => c.detail).join('; ');
    box.append(p);
  }
  const list = document.createElement('ul');
  for (const r of regions) {
    const li = document.createElement('li');
    const tag = document.createElement('span');
    tag.className = `tag ${r.verdict.replace(/_$/, '')}`;
    tag.textContent = r.verdict.replace(/_$/, '');
    const words = document.createElement('span');
    words.textContent = r.reason;
    li.append(tag, words);
    list.append(li);
  }
  box.append(list);
  box.hidden = false;
}

// ---- Fit map -------------------------------------------------------------------------------------

function renderLegend(legends) {
  const box = $('legend');
  box.replaceChildren();
  for (const part of ['garment', 'body']) {
    const l = legends && legends[part];
    if (!l) continue;
    const row = document.createElement('div');
    row.className = 'scale';
    const title = document.createElement('span');
    title.textContent = `${part === 'garment' ? 'Cloth' : 'Skin'}: ${l.title}`;
    const ramp = document.createElement('div');
    ramp.className = 'ramp';
    ramp.style.background = `linear-gradient(to right, ${l.stops.join(', ')})`;
    const ends = document.createElement('div');
    ends.className = 'ends';
    const lo = document.createElement('span');
    lo.textContent = `${l.lo}`;
    const hi = document.createElement('span');
    hi.textContent = `${l.hi}`;
    ends.append(lo, hi);
    row.append(title, ramp, ends);
    box.append(row);
  }
}

function setFitMap(on) {
  state.showFit = on;
  $('fitmap').setAttribute('aria-pressed', String(on));
  $('fitmap').textContent = on ? 'Hide fit map' : 'Show fit map';
  $('legend').hidden = !on;
}

$('fitmap').addEventListener('click', async () => {
  if (!state.tryon || state.tryon.state !== 'done') return;
  const on = !state.showFit;
  try {
    if (on && !state.fit) state.fit = dress(await loadGlb(state.tryon.files.fit), true);
    setFitMap(on);
    renderLegend(state.tryon.report.legends);
    show(on ? state.fit : state.dressed, on ? 'fitmap' : 'dressed');
  } catch (e) { showError(e.message); }
});

// ---- Share link: the measurements, garment and size in the address --------------------------------

function shareUrl() {
  const q = new URLSearchParams({ sex: state.bodyRequest.sex });
  for (const [k, v] of Object.entries(state.bodyRequest.measurements)) q.set(k, String(v));
  q.set('garment', state.garment.name);
  q.set('size', state.size);
  return `${location.origin}${location.pathname}?${q}`;
}
$('share').addEventListener('click', async () => {
  const url = shareUrl();
  history.replaceState(null, '', url);
  try {
    await navigator.clipboard.writeText(url);
    $('share-note').textContent = 'Link copied: it opens this try-on from your measurements.';
  } catch {
    $('share-note').textContent = `Share this link: ${url}`;
  }
});

// ---- Start ---------------------------------------------------------------------------------------

async function start() {
  setDefaults('female');
  try {
    state.garments = (await api('/api/garments')).data.garments;
  } catch (e) { showError(e.message); return; }
  renderCatalogue();
  const q = new URLSearchParams(location.search);
  if (q.get('sex') === 'male') { measureForm().elements.sex.value = 'male'; setDefaults('male'); }
  const shared = {};
  for (const k of ['height', 'bust', 'waist', 'hips']) {
    const v = Number(q.get(k));
    if (q.has(k) && Number.isFinite(v)) { shared[k] = v; measureForm().elements[k].value = Math.round(v * 1000) / 10; }
  }
  selectGarment(q.get('garment') || (state.garments[0] && state.garments[0].name), q.get('size'));
  document.body.dataset.ready = 'true';
  // A shared link reproduces the try-on: the same measurements, garment and size.
  if (Object.keys(shared).length && q.get('garment') && q.get('size')) {
    await makeBody({ sex: sex(), measurements: shared });
    if (state.body && state.size) await tryOn();
  }
}
start();
