// The page around rastergi's WebGPU renderer (crates/rastergi-web): the animation-frame
// loop, the panel, the mouse and keys, dropped or picked files, and "save PNG".
//
// URL parameters (all optional): scene (a built-in name), width, height, seed, gather
// (lists | trace), denoise (1: start with the denoiser on), iterations (stop after this many;
// the test uses it). The page publishes
// `window.rastergi` = { ready (a promise), viewer, samples(), error(), png(raw) } for
// scripts/web-test.sh (png(true): the film's image unfiltered while the denoised one is shown).
import init, { createViewer } from './pkg/rastergi_web.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const canvas = $('view');
const state = { viewer: null, limit: Number(params.get('iterations') || 0), error: '', estimate: null };
window.rastergi = {
  get viewer() { return state.viewer; },
  samples: () => (state.viewer ? state.viewer.samples() : 0),
  error: () => state.error,
  idle: () => (state.viewer ? state.viewer.idle() : false),
  png: async (raw = false) => {
    const bytes = await state.viewer.savePng(raw);
    let text = '';
    for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
    return btoa(text);
  },
};

function showError(e) {
  state.error = String(e && e.message ? e.message : e);
  $('error').textContent = state.error;
  $('error').hidden = false;
}

function clearError() {
  state.error = '';
  $('error').hidden = true;
}

function showWarnings() {
  const list = $('warnings');
  for (const w of state.viewer.takeWarnings()) {
    const li = document.createElement('li');
    li.textContent = w;
    list.append(li);
  }
}

// Runs a change to the viewer; its error goes to the page's error line.
function apply(change) {
  try {
    change();
    clearError();
  } catch (e) {
    showError(e);
  }
  if (state.viewer) {
    showWarnings();
    refreshPanel();
  }
}

function refreshPanel() {
  const v = state.viewer;
  $('status').textContent = v.describe();
  const sun = v.sun();
  $('sun-controls').hidden = sun === '';
  if (sun !== '') {
    const [a, e] = sun.split(',');
    $('sun-azimuth').value = a;
    $('sun-elevation').value = e;
    $('sun-azimuth-value').textContent = `${a}°`;
    $('sun-elevation-value').textContent = `${e}°`;
  }
}

function setImageSize(w, h) {
  canvas.width = w;
  canvas.height = h;
  state.viewer.resizeCanvas(w, h);
}

async function loadFiles(fileList) {
  const files = [...fileList];
  if (files.length === 0) return;
  const contents = await Promise.all(files.map(async (f) => new Uint8Array(await f.arrayBuffer())));
  apply(() => {
    state.viewer.loadFiles(files.map((f) => f.name), contents);
    $('warnings').replaceChildren();
  });
}

// Iterations per second over the last second, and the error estimate about once a second.
const rate = { since: performance.now(), samples: 0 };
let pendingEstimate = false;

function updateStats(samples) {
  $('iterations').textContent = `${samples} iteration${samples === 1 ? '' : 's'}`;
  document.body.dataset.samples = samples;
  const now = performance.now();
  if (samples < rate.samples) Object.assign(rate, { since: now, samples });
  if (now - rate.since >= 1000) {
    const per = ((samples - rate.samples) * 1000) / (now - rate.since);
    $('rate').textContent = `${per.toFixed(1)} iterations/s`;
    Object.assign(rate, { since: now, samples });
    if (!pendingEstimate && samples >= 8) {
      pendingEstimate = true;
      state.viewer.errorEstimate().then((e) => {
        state.estimate = e;
        $('error-estimate').textContent = e === null ? 'error: estimated after a few photon passes' : `error ≈ ${(100 * e).toFixed(1)} %`;
      }).catch(showError).finally(() => { pendingEstimate = false; });
    }
  }
}

const held = new Set();
let last = performance.now();

function frame(now) {
  const v = state.viewer;
  const dt = Math.min((now - last) / 1000, 0.1);
  last = now;
  try {
    if (held.size) {
      const keys = [...held].join('') + (held.has('SHIFT') ? 'F' : '');
      v.fly(keys, dt);
    }
    updateStats(v.frame(state.limit));
  } catch (e) {
    showError(e);
  }
  requestAnimationFrame(frame);
}

function wire() {
  const v = () => state.viewer;
  $('scene').addEventListener('change', (e) => apply(() => v().loadBuiltin(e.target.value)));
  $('files').addEventListener('change', async (e) => {
    await loadFiles(e.target.files);
    // Picking the same files again is a change too.
    e.target.value = '';
  });
  for (const key of ['method', 'gather', 'photons', 'show']) {
    $(key).addEventListener('change', (e) => apply(() => v().set(key, e.target.value)));
  }
  $('denoise').addEventListener('change', (e) => apply(() => {
    try {
      v().set('denoise', e.target.checked ? 'on' : 'off');
    } catch (err) {
      e.target.checked = false; // the denoiser stays off
      throw err;
    }
  }));
  $('size').addEventListener('change', (e) => apply(() => {
    v().set('size', e.target.value);
    const [w, h] = e.target.value.split('x').map(Number);
    setImageSize(w, h);
  }));
  $('exposure').addEventListener('input', (e) => {
    $('exposure-value').textContent = e.target.value;
    apply(() => v().set('exposure', e.target.value));
  });
  for (const id of ['sun-azimuth', 'sun-elevation']) {
    $(id).addEventListener('change', () => apply(() => v().set('sun', `${$('sun-azimuth').value},${$('sun-elevation').value}`)));
  }
  $('home').addEventListener('click', () => apply(() => v().home()));
  $('mode').addEventListener('click', () => {
    const mode = v().toggleMode();
    $('mode').textContent = mode === 'fly' ? 'orbit mode' : 'fly mode';
  });
  $('save').addEventListener('click', async () => {
    try {
      const bytes = await v().savePng(false);
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([bytes], { type: 'image/png' }));
      a.download = `rastergi-${v().sceneName().replace(/[^\w.-]+/g, '_')}-${v().samples()}.png`;
      a.click();
      URL.revokeObjectURL(a.href);
    } catch (e) {
      showError(e);
    }
  });

  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
    canvas.focus();
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const scale = canvas.width / canvas.clientWidth;
    apply(() => v().drag((e.clientX - drag.x) * scale, (e.clientY - drag.y) * scale));
    drag = { x: e.clientX, y: e.clientY };
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    apply(() => v().zoom(-Math.sign(e.deltaY)));
  }, { passive: false });
  const flyKey = (e) => (e.key === 'Shift' ? 'SHIFT' : e.key.length === 1 ? e.key.toUpperCase() : '');
  canvas.addEventListener('keydown', (e) => {
    const k = flyKey(e);
    if ('WASDEQ'.includes(k) || k === 'SHIFT') held.add(k);
  });
  canvas.addEventListener('keyup', (e) => held.delete(flyKey(e)));
  canvas.addEventListener('blur', () => held.clear());

  const stage = $('stage');
  document.addEventListener('dragover', (e) => { e.preventDefault(); stage.classList.add('dragging'); });
  document.addEventListener('dragleave', () => stage.classList.remove('dragging'));
  document.addEventListener('drop', (e) => {
    e.preventDefault();
    stage.classList.remove('dragging');
    loadFiles(e.dataTransfer.files);
  });
}

async function main() {
  if (!navigator.gpu) {
    throw new Error('this browser has no WebGPU: use a recent Chrome or Edge, Safari 26, or Firefox 141+ (on Linux, Chrome needs --enable-unsafe-webgpu)');
  }
  await init();
  const width = Number(params.get('width') || 512);
  const height = Number(params.get('height') || width);
  canvas.width = width;
  canvas.height = height;
  $('size').value = `${width}x${height}`;
  state.viewer = await createViewer(canvas, width, height, Number(params.get('seed') || 0));
  wire();
  if (params.get('gather')) {
    $('gather').value = params.get('gather');
    state.viewer.set('gather', params.get('gather'));
  }
  if (params.get('denoise') === '1') {
    $('denoise').checked = true;
    state.viewer.set('denoise', 'on');
  }
  if (params.get('scene') && params.get('scene') !== 'cornell') {
    $('scene').value = params.get('scene');
    state.viewer.loadBuiltin(params.get('scene'));
  }
  showWarnings();
  refreshPanel();
  requestAnimationFrame(frame);
}

window.rastergi.ready = main().catch((e) => {
  showError(e);
  $('status').textContent = 'rastergi could not start';
});
