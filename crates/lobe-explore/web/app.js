// lobe explore: the browser side of `lobe explore`.
//
// Plain JavaScript, no build step. The page keeps a list of materials (Mitsuba 3
// style descriptions), a viewing direction (θo, φo) and a few options; every
// change asks the server (a JSON API under api/) for the data of each view and
// redraws it with Plotly (or on a canvas for the lit sphere).
//
// Structure:
//   1. constants and small helpers
//   2. the API client and the error box
//   3. state: models, materials and their descriptions
//   4. scheduling: debounced, cancellable view runs (latest wins)
//   5. one function per view (fetch + draw)
//   6. the material panels and their parameter controls
//   7. the global controls, the data panel and start-up
//
// Tests read `window.lobeExplore` ({ready, errors}) and each view element's
// `data-version` (redraws with new server data) and `data-ms` (milliseconds
// from the input event to the end of that redraw).

'use strict';

window.lobeExplore = { ready: false, errors: [] };

// ---------------------------------------------------------------------------
// 1. Constants and helpers
// ---------------------------------------------------------------------------

/** Delay of the cheap views after an input event (at most this long). */
const CHEAP_DELAY_MS = 30;
/** Quiet time before the heavy views (warp, estimate) are requested. */
const HEAVY_DELAY_MS = 250;
/** Passes of the progressive lit sphere, and its size in pixels. */
const SPHERE_PASSES = 32;
const SPHERE_SIZE = 128;

const CHEAP_VIEWS = ['describe', 'polar', 'lobe3d', 'albedo', 'sphere'];
const HEAVY_VIEWS = ['warp', 'estimate'];
const ALL_VIEWS = [...CHEAP_VIEWS, ...HEAVY_VIEWS];

/** θo's upper bound for a reflecting and for a transmitting active material. */
const THETA_MAX_REFLECT = 89;
const THETA_MAX_TRANSMIT = 179;

/** Colours of the materials in the overlaid plots. */
const PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd',
  '#8c564b', '#e377c2', '#17becf', '#bcbd22', '#7f7f7f'];
/** Dash patterns of the active material's pdfs in the polar plot. */
const DASHES = ['dash', 'dot', 'dashdot', 'longdash', 'longdashdot', '8px,3px,2px,3px'];
/** Channel colours for the active material's RGB albedo. */
const RGB_COLOURS = ['#e41a1c', '#4daf4a', '#377eb8'];
/** Rec. 709 luminance weights. */
const LUMA = [0.2126, 0.7152, 0.0722];
/** Strategies preferred for the warp test when the user has not chosen one. */
const PREFERRED_STRATEGIES = ['vndf', 'bounded-vndf', 'spherical-caps', 'brdf', 'cosine', 'uniform'];

const PLOT_CONFIG = {
  responsive: true,
  displaylogo: false,
  modeBarButtonsToRemove: ['lasso2d', 'select2d'],
};

/** The small warp heatmaps: no mode bar. */
const WARP_CONFIG = { ...PLOT_CONFIG, displayModeBar: false };

const $ = (selector) => document.querySelector(selector);
const hasOwn = (object, key) => Object.prototype.hasOwnProperty.call(object, key);
const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
const isNum = (v) => typeof v === 'number' && Number.isFinite(v);
const round3 = (v) => Number(v.toPrecision(3));
const radians = (deg) => (deg * Math.PI) / 180;

/**
 * Create an element: h('div', {class: 'x', title: 'y'}, child, 'text', ...).
 * Attributes that are null, undefined or false are left out; true sets an
 * empty attribute.
 */
function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === null || value === undefined || value === false) continue;
    if (key === 'class') el.className = value;
    else el.setAttribute(key, value === true ? '' : String(value));
  }
  for (const child of children.flat()) {
    if (child === null || child === undefined || child === false) continue;
    el.append(child instanceof Node ? child : String(child));
  }
  return el;
}

/** A number for people: 3 significant digits, exponent when very small or large. */
function fmt(v, digits = 3) {
  if (v === null || v === undefined) return '—';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return String(v);
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e5 || a < 1e-3) return v.toExponential(digits - 1);
  return String(Number(v.toPrecision(digits)));
}

/** Luminance of [r, g, b] (or of a grey number). */
function luminance(c) {
  if (isNum(c)) return c;
  if (!Array.isArray(c)) return null;
  let sum = 0;
  for (let k = 0; k < 3; k += 1) {
    if (!isNum(c[k])) return null;
    sum += LUMA[k] * c[k];
  }
  return sum;
}

/** Linear → sRGB-encoded, both in [0, 1]. */
function srgbEncode(x) {
  const c = clamp(x, 0, 1);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055;
}

/** Largest finite number of an array (0 when none). */
function maxOf(values) {
  let m = 0;
  if (!Array.isArray(values)) return m;
  for (const v of values) if (isNum(v) && v > m) m = v;
  return m;
}

// ---------------------------------------------------------------------------
// 2. The API client and the error box
// ---------------------------------------------------------------------------

/** An error answered by the server (HTTP 4xx/5xx with {"error": message}). */
class ApiError extends Error {
  constructor(message, status = 0) {
    super(message);
    this.name = 'ApiError';
    this.status = status;
  }
}

const isAbort = (e) => Boolean(e) && e.name === 'AbortError';
const abortError = () => new DOMException('superseded by a newer request', 'AbortError');

/**
 * GET (no body) or POST a JSON body to `path`; resolves to the parsed JSON
 * answer. Rejects with an AbortError when `signal` aborts (also after the
 * answer arrived, so that a stale answer is never drawn) and with an
 * ApiError carrying the server's message otherwise.
 */
async function api(path, body, signal) {
  for (let attempt = 0; ; attempt += 1) {
    try {
      return await apiOnce(path, body, signal);
    } catch (e) {
      // 503: too many requests waiting at the server; wait a little, retry.
      if (!(e instanceof ApiError) || e.status !== 503 || attempt >= 3) throw e;
      await new Promise((resolve) => { setTimeout(resolve, 150 * (attempt + 1)); });
      if (signal && signal.aborted) throw abortError();
    }
  }
}

/** One request of api() (no retry). */
async function apiOnce(path, body, signal) {
  const options = body === undefined
    ? { signal }
    : {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify(body),
      signal,
    };
  let response;
  try {
    response = await fetch(path, options);
  } catch (e) {
    if (isAbort(e) || (signal && signal.aborted)) throw abortError();
    throw new ApiError(`${path}: the server could not be reached (${e.message})`);
  }
  let data = null;
  try {
    data = await response.json();
  } catch (e) {
    if (isAbort(e) || (signal && signal.aborted)) throw abortError();
    data = null;
  }
  if (signal && signal.aborted) throw abortError();
  if (!response.ok) {
    const message = data && typeof data.error === 'string'
      ? data.error
      : `${path}: HTTP ${response.status} ${response.statusText}`.trim();
    throw new ApiError(message, response.status);
  }
  if (data === null || typeof data !== 'object') {
    throw new ApiError(`${path}: the answer is not a JSON object`, response.status);
  }
  return data;
}

/** Which view (or action) the message in #error belongs to. */
let errorOwner = null;

/** Show a message in #error; an API error is also pushed onto lobeExplore.errors. */
function showError(message, owner, fromApi = true) {
  if (fromApi) window.lobeExplore.errors.push(message);
  const box = $('#error');
  box.textContent = message;
  box.hidden = false;
  errorOwner = owner;
}

/** Clear #error if `owner` put the message there (its next success). */
function clearError(owner) {
  if (errorOwner !== owner) return;
  const box = $('#error');
  box.textContent = '';
  box.hidden = true;
  errorOwner = null;
}

/** Show any failure of a view or action; aborts are not errors. */
function reportFailure(err, owner) {
  if (isAbort(err)) return;
  if (err instanceof ApiError) {
    showError(err.message, owner, true);
  } else {
    // A failure in the page itself (a drawing library refusing, say): shown,
    // but not counted as an API error.
    showError(`${owner}: ${err && err.message ? err.message : String(err)}`, owner, false);
  }
}

// ---------------------------------------------------------------------------
// 3. State: models, materials and descriptions
// ---------------------------------------------------------------------------

const state = {
  /** name → {name, doc, params: [P], example} from api/models. */
  models: new Map(),
  /** name → {name, description} of the sampling strategies. */
  strategies: new Map(),
  /** [{path, kind: 'measured' | 'envmap'}]. */
  dataFiles: [],
  /**
   * The materials: {uid, type, values, twosided, colour, label, note}.
   * `values` holds only the params the user (or the model's example, or a
   * fit) set to something other than the default.
   */
  materials: [],
  active: 0,
  nextUid: 1,
  thetaO: 30,
  phiO: 0,
  polarLog: false,
  env: 'sky',
  exposure: 0,
  warpStrategy: null,
  describeFormat: 'json',
  /** The last api/material answer for the active material. */
  describeData: null,
};

function modelOf(m) { return state.models.get(m.type) || null; }
function paramsOf(m) { const model = modelOf(m); return model ? model.params : []; }

/** Model names offered in a material's select ("twosided" is the checkbox). */
function modelNames() { return [...state.models.keys()].filter((n) => n !== 'twosided'); }

/** A colour value as [r, g, b]: from a grey number, an array or {"type":"rgb","value":…}. */
function colourArray(v) {
  if (isNum(v)) return [v, v, v];
  if (Array.isArray(v) && v.length === 3 && v.every(isNum)) return v.slice();
  if (v && typeof v === 'object' && !Array.isArray(v) && hasOwn(v, 'value')) return colourArray(v.value);
  return null;
}

/** A value in its shortest form: a grey colour as one number. */
function canonical(P, v) {
  if (P && P.kind === 'colour') {
    const c = colourArray(v);
    if (c && c[0] === c[1] && c[1] === c[2]) return c[0];
    return c || v;
  }
  return v;
}

function sameValue(P, a, b) {
  return JSON.stringify(canonical(P, a)) === JSON.stringify(canonical(P, b));
}

/** The first palette colour not in use. */
function nextColour() {
  const used = new Set(state.materials.map((m) => m.colour));
  return PALETTE.find((c) => !used.has(c)) || PALETTE[state.materials.length % PALETTE.length];
}

/**
 * A material from a description (a two-sided one is unwrapped and its
 * checkbox set). Values equal to the model's defaults are left out.
 */
function materialFromDescription(description, extra = {}) {
  let d = description && typeof description === 'object' ? description : {};
  let twosided = false;
  if (d.type === 'twosided' && d.bsdf && typeof d.bsdf === 'object') {
    twosided = true;
    d = d.bsdf;
  }
  const m = {
    uid: state.nextUid++,
    type: String(d.type || ''),
    values: {},
    twosided,
    colour: extra.colour || nextColour(),
    label: extra.label || null,
    note: extra.note || null,
  };
  const params = new Map(paramsOf(m).map((P) => [P.name, P]));
  for (const [key, value] of Object.entries(d)) {
    if (key === 'type') continue;
    const P = params.get(key);
    if (P && P.default !== undefined && P.default !== null && sameValue(P, value, P.default)) continue;
    m.values[key] = P ? canonical(P, value) : value;
  }
  return m;
}

/**
 * The description sent to the server: "type", then the set params in the
 * model's order, then any other keys (a fit's, say); wrapped as
 * {"type":"twosided","bsdf":…} when two-sided.
 */
function describe(m) {
  const d = { type: m.type };
  for (const P of paramsOf(m)) if (hasOwn(m.values, P.name)) d[P.name] = m.values[P.name];
  for (const [key, value] of Object.entries(m.values)) if (!hasOwn(d, key)) d[key] = value;
  return m.twosided ? { type: 'twosided', bsdf: d } : d;
}

const descriptionKey = (desc) => JSON.stringify(desc);

/** The legend name of material `m` at `index` (kept short for the legends). */
function legendName(m, index) {
  // A measured material is named by its file.
  const file = m.label ? null : fileOf(m);
  const name = m.label || (file ? `${m.type} ${file.split('/').pop()}` : m.type);
  let text = `${name}${m.twosided ? ', two-sided' : ''}`;
  if (text.length > 26) text = `${text.slice(0, 25)}…`;
  return `${index + 1}. ${text}`;
}

/** The measured model and its file param, if the server has one. */
function measuredModel() {
  for (const model of state.models.values()) {
    const P = model.params.find((p) => p.kind === 'file');
    if (P) return { model, param: P };
  }
  return null;
}

/** The data file of a measured material, or null. */
function fileOf(m) {
  const P = paramsOf(m).find((p) => p.kind === 'file');
  if (!P) return null;
  const v = m.values[P.name];
  return typeof v === 'string' && v ? v : null;
}

/** Is `desc` the active material's current description? */
function isCurrentActive(desc) {
  const m = state.materials[state.active];
  return Boolean(m) && descriptionKey(describe(m)) === descriptionKey(desc);
}

/** The controller of a running api/fit request (the #fit button waits for it). */
let fitController = null;

// api/material answers by description: {model, strategies, transmits, ...}.
const infoCache = new Map();

/** The api/material answer for `desc`, cached (a failed one is forgotten). */
function infoFor(desc) {
  const key = descriptionKey(desc);
  let promise = infoCache.get(key);
  if (!promise) {
    promise = api('api/material', { material: desc });
    rememberInfo(key, promise);
    promise.catch(() => { if (infoCache.get(key) === promise) infoCache.delete(key); });
  }
  return promise;
}

function rememberInfo(key, promise) {
  infoCache.set(key, promise);
  if (infoCache.size > 256) infoCache.delete(infoCache.keys().next().value);
}

// ---------------------------------------------------------------------------
// 4. Scheduling: debounced, cancellable view runs
// ---------------------------------------------------------------------------

/** Per view: the running request's controller, the version, drawn yet. */
const runtime = Object.fromEntries(ALL_VIEWS.map((v) => [v, { controller: null, version: 0, drawn: false, key: null }]));

/** The view functions, by element id (filled in section 5). */
const VIEW_FUNCTIONS = {};

/** performance.now() of the last input event (start of each data-ms). */
let lastInput = performance.now();
const pendingCheap = new Set();
const pendingHeavy = new Set();
let cheapTimer = null;
let heavyTimer = null;
/**
 * How long the server has been taking to answer the cheap views (a moving
 * average): while a slider moves they are sent no more often than that, so
 * that they finish (and draw) instead of piling up at the server.
 */
let cheapLatency = 0;
/** The longest the cheap views wait for that. */
const CHEAP_MAX_DELAY_MS = 150;

/**
 * Something changed: request `views` again. The cheap ones run
 * CHEAP_DELAY_MS later (no more often than the server answers them while a
 * slider moves, so that a dragged slider updates them continuously), the
 * heavy ones after HEAVY_DELAY_MS without a further change (or CHEAP_DELAY_MS
 * when `soon`); the heavy ones in flight are stale and cancelled now.
 */
function changed(views = ALL_VIEWS, { soon = false } = {}) {
  lastInput = performance.now();
  for (const v of views) {
    if (HEAVY_VIEWS.includes(v)) {
      pendingHeavy.add(v);
      abortView(v);
    } else {
      pendingCheap.add(v);
    }
  }
  if (pendingCheap.size && cheapTimer === null) {
    // While the last cheap run is still under way, pace by the server.
    const busy = CHEAP_VIEWS.some((v) => v !== 'sphere' && runtime[v].controller);
    const delay = busy ? clamp(cheapLatency, CHEAP_DELAY_MS, CHEAP_MAX_DELAY_MS) : CHEAP_DELAY_MS;
    cheapTimer = setTimeout(flushCheap, delay);
  }
  if (pendingHeavy.size) {
    clearTimeout(heavyTimer);
    heavyTimer = setTimeout(flushHeavy, soon ? CHEAP_DELAY_MS : HEAVY_DELAY_MS);
  }
}

function abortView(name) {
  const rt = runtime[name];
  if (rt.controller) {
    rt.controller.abort();
    rt.controller = null;
  }
}

function flushCheap() {
  cheapTimer = null;
  const views = [...pendingCheap];
  pendingCheap.clear();
  const snap = snapshot();
  for (const v of views) {
    // The sphere's request has neither θo nor φo: restart it only when what
    // it draws changed (or its last run failed).
    if (v === 'sphere' && runtime.sphere.key === sphereKey(snap)) continue;
    startView(v, snap);
  }
}

function flushHeavy() {
  heavyTimer = null;
  const views = [...pendingHeavy];
  pendingHeavy.clear();
  const snap = snapshot();
  for (const v of views) startView(v, snap);
}

/** The state a run works from (later changes do not affect it). */
function snapshot() {
  return {
    t0: lastInput,
    materials: state.materials.map((m, index) => ({
      m, index, desc: describe(m), colour: m.colour, name: legendName(m, index),
    })),
    active: state.active,
    thetaO: state.thetaO,
    phiO: state.phiO,
    polarLog: state.polarLog,
    env: state.env,
  };
}

const activeOf = (snap) => snap.materials[snap.active];

/**
 * Start view `name` on `snap`, cancelling its previous run (latest wins).
 * The view function asks the server through ctx.api() and calls
 * ctx.drawn() after each redraw; it may return an error message to show
 * for a partial failure.
 */
function startView(name, snap) {
  const rt = runtime[name];
  if (rt.controller) rt.controller.abort();
  const controller = new AbortController();
  rt.controller = controller;
  if (name === 'sphere') rt.key = sphereKey(snap);
  const el = document.getElementById(name);
  const cheap = CHEAP_VIEWS.includes(name);
  const ctx = {
    snap,
    signal: controller.signal,
    /** api() with this run's signal; a cheap view's answer time is noted. */
    async api(path, body) {
      const start = performance.now();
      const data = await api(path, body, controller.signal);
      if (cheap) cheapLatency = 0.7 * cheapLatency + 0.3 * (performance.now() - start);
      return data;
    },
    drawn() {
      if (controller.signal.aborted) return;
      rt.version += 1;
      el.dataset.version = String(rt.version);
      el.dataset.ms = String(Math.round(performance.now() - snap.t0));
      clearError(name);
      markDrawn(name);
    },
  };
  Promise.resolve()
    .then(() => VIEW_FUNCTIONS[name](ctx))
    .then(
      (partialError) => {
        if (!controller.signal.aborted && partialError) showError(partialError, name, true);
      },
      (err) => {
        if (isAbort(err) || controller.signal.aborted) return;
        if (name === 'sphere') rt.key = null; // retry on the next change
        reportFailure(err, name);
      },
    )
    .finally(() => {
      if (rt.controller === controller) rt.controller = null;
    });
}

/** Note a view's first draw; ready once every view has drawn. */
function markDrawn(name) {
  runtime[name].drawn = true;
  if (!window.lobeExplore.ready && ALL_VIEWS.every((v) => runtime[v].drawn)) {
    window.lobeExplore.ready = true;
    document.body.dataset.ready = 'true';
  }
}

/**
 * Before a view that depends on θo asks the server: when θo is past 89°
 * (only allowed for a transmitting material), make sure the active material
 * transmits, else clamp θo and let the new run do the work. With
 * `needInfo`, always return the active material's api/material answer.
 */
async function guard(ctx, { needInfo = false } = {}) {
  const { snap } = ctx;
  if (!needInfo && snap.thetaO <= THETA_MAX_REFLECT) return null;
  const a = activeOf(snap);
  const info = await infoFor(a.desc);
  if (ctx.signal.aborted || !isCurrentActive(a.desc)) throw abortError();
  const clamped = applyThetaRange(Boolean(info.transmits));
  if (clamped || (!info.transmits && snap.thetaO > THETA_MAX_REFLECT)) {
    // This run's θo is out of the material's range: a new run (with θo
    // clamped, by this view or another) replaces it.
    if (clamped) changed();
    throw abortError();
  }
  return info;
}

/**
 * θo's range: 0–89°, or 0–179° when the active material transmits. Returns
 * true when θo had to be clamped.
 */
function applyThetaRange(transmits) {
  const el = $('#theta-o');
  const max = transmits ? THETA_MAX_TRANSMIT : THETA_MAX_REFLECT;
  if (Number(el.max) !== max) el.max = String(max);
  if (state.thetaO > max) {
    state.thetaO = max;
    el.value = String(max);
    showAngles();
    return true;
  }
  return false;
}

/** Fill #warp-strategy with `names`; returns the strategy to use (or null). */
function setStrategies(names) {
  const list = Array.isArray(names) ? names : [];
  const select = $('#warp-strategy');
  const key = list.join(',');
  if (select.dataset.key !== key) {
    select.replaceChildren(...list.map((n) => {
      const s = state.strategies.get(n);
      return h('option', { value: n, title: s && s.description ? s.description : null }, n);
    }));
    if (!list.length) select.append(h('option', { value: '' }, 'none (delta lobe)'));
    select.disabled = list.length === 0;
    select.dataset.key = key;
  }
  if (!list.includes(state.warpStrategy)) {
    state.warpStrategy = PREFERRED_STRATEGIES.find((n) => list.includes(n)) || list[0] || null;
  }
  select.value = state.warpStrategy || '';
  return state.warpStrategy;
}

// ---------------------------------------------------------------------------
// 5. The views: one function each (fetch, then draw)
// ---------------------------------------------------------------------------

/** Layout defaults shared by the plots. */
function baseLayout(extra = {}) {
  return {
    font: { family: 'system-ui, -apple-system, "Segoe UI", sans-serif', size: 11, color: '#222' },
    paper_bgcolor: 'rgba(0,0,0,0)',
    margin: { l: 55, r: 15, t: 20, b: 45 },
    hovermode: 'closest',
    ...extra,
  };
}

function plotlyReady() {
  if (!window.Plotly) throw new Error('Plotly did not load (vendor/plotly.min.js)');
  return window.Plotly;
}

/** Ask api/`path` for every material of `entries`; failures are kept per material. */
async function perMaterial(ctx, path, entries, body) {
  return Promise.all(entries.map((e) => ctx.api(path, { material: e.desc, ...body }).then(
    (data) => ({ e, data }),
    (err) => {
      if (isAbort(err)) throw err;
      return { e, err };
    },
  )));
}

/** Split per-material results: the ones to draw, and the first error message. */
function splitResults(results) {
  const ok = results.filter((r) => r.data);
  const failed = results.find((r) => r.err);
  if (!ok.length && failed) throw failed.err;
  return { ok, error: failed ? failed.err.message : null };
}

// --- #describe: the active material's description in JSON, TOML, Python ----

VIEW_FUNCTIONS.describe = async function viewDescribe(ctx) {
  const a = activeOf(ctx.snap);
  const info = await ctx.api('api/material', { material: a.desc });
  rememberInfo(descriptionKey(a.desc), Promise.resolve(info));
  state.describeData = info;
  renderDescription();
  const facts = [
    `model ${info.model || a.m.type}`,
    info.transmits ? 'transmits' : 'reflects only',
    info.two_sided ? 'two-sided' : null,
    info.anisotropic === true ? 'anisotropic' : null,
    `strategies: ${(info.strategies || []).join(', ') || 'none (delta lobe)'}`,
  ];
  $('#material-info').textContent = facts.filter(Boolean).join(' · ');
  ctx.drawn();
  if (isCurrentActive(a.desc)) {
    setStrategies(info.strategies);
    if (applyThetaRange(Boolean(info.transmits))) changed();
  }
};

/** Show the chosen format of the last description in the textarea. */
function renderDescription() {
  const d = state.describeData;
  const text = d && typeof d[state.describeFormat] === 'string' ? d[state.describeFormat] : '';
  $('#description').value = text;
  for (const f of ['json', 'toml', 'python']) {
    $(`#copy-${f}`).classList.toggle('selected', f === state.describeFormat);
  }
}

/** Show `format` and copy it; without a clipboard, select the text instead. */
async function copyDescription(format) {
  state.describeFormat = format;
  renderDescription();
  const area = $('#description');
  const status = $('#copy-status');
  const label = { json: 'JSON', toml: 'TOML', python: 'Python' }[format];
  try {
    if (!navigator.clipboard || !window.isSecureContext) throw new Error('no clipboard');
    await navigator.clipboard.writeText(area.value);
    status.textContent = `${label} copied`;
  } catch {
    area.focus();
    area.select();
    let copied = false;
    try { copied = document.execCommand('copy'); } catch { copied = false; }
    status.textContent = copied ? `${label} copied` : `${label} selected: press Ctrl+C to copy`;
  }
}

// --- #polar: f·|cos θi| of every material, the active one's pdfs ------------

VIEW_FUNCTIONS.polar = async function viewPolar(ctx) {
  const { snap } = ctx;
  await guard(ctx);
  let entries = snap.materials;
  if (snap.thetaO > 90) entries = await seenFromBelow(snap, ctx.signal);
  const results = await perMaterial(ctx, 'api/polar', entries, { theta_o: snap.thetaO, phi_o: snap.phiO });
  const { ok, error } = splitResults(results);
  await drawPolar(snap, ok);
  ctx.drawn();
  return error;
};

/**
 * With the viewer below the surface (θo > 90°, a transmitting active
 * material) the materials that only reflect (and are not two-sided) have
 * nothing to show: leave them out of the overlay.
 */
async function seenFromBelow(snap, signal) {
  const keep = await Promise.all(snap.materials.map((e) => {
    if (e.index === snap.active || e.m.twosided) return true;
    return infoFor(e.desc).then((info) => Boolean(info.transmits || info.two_sided), () => true);
  }));
  if (signal.aborted) throw abortError();
  return snap.materials.filter((_, i) => keep[i]);
}

function drawPolar(snap, results) {
  const Plotly = plotlyReady();
  const log = snap.polarLog;
  const radius = (v) => (isNum(v) && (log ? v > 0 : true) ? v : null);
  let rMax = 0;
  let rMin = Infinity;
  const track = (values) => {
    for (const v of values) {
      if (v !== null && v > 0) {
        if (v > rMax) rMax = v;
        if (v < rMin) rMin = v;
      }
    }
  };
  let full = false;
  const traces = [];
  for (const { e, data } of results) {
    full = full || Boolean(data.full_circle);
    const isActive = e.index === snap.active;
    const r = (data.fcos || []).map(radius);
    track(r);
    const albedo = isNum(data.albedo) ? ` (albedo ${fmt(data.albedo)})` : '';
    traces.push({
      type: 'scatterpolar',
      mode: 'lines',
      name: `${e.name}${albedo}`,
      r,
      theta: data.theta_deg || [],
      line: { color: e.colour, width: isActive ? 2.5 : 1.5 },
      hovertemplate: 'θi %{theta:.1f}°<br>f·|cos θi| %{r:.4g} /sr<extra>%{fullData.name}</extra>',
    });
    if (isActive && data.pdfs && typeof data.pdfs === 'object') {
      Object.entries(data.pdfs).forEach(([strategy, pdf], k) => {
        const rp = (pdf || []).map(radius);
        track(rp);
        traces.push({
          type: 'scatterpolar',
          mode: 'lines',
          name: `pdf ${strategy}`,
          r: rp,
          theta: data.theta_deg || [],
          line: { color: e.colour, width: 1.2, dash: DASHES[k % DASHES.length] },
          opacity: 0.8,
          hovertemplate: 'θi %{theta:.1f}°<br>pdf %{r:.4g} /sr<extra>%{fullData.name}</extra>',
        });
      });
    }
  }
  // The viewing direction: a dotted radius at θi = θo, a dot at its end.
  if (rMax > 0) {
    traces.push({
      type: 'scatterpolar',
      mode: 'lines+markers',
      name: `viewer, θo = ${snap.thetaO}°`,
      r: [log ? rMin : 0, rMax * 1.05],
      theta: [snap.thetaO, snap.thetaO],
      line: { color: '#333333', width: 1, dash: 'dot' },
      marker: { size: [0, 9], color: '#333333' },
      hoverinfo: 'name',
    });
  }
  const ticks = [];
  for (let t = full ? -150 : -90; t <= (full ? 180 : 90); t += 30) ticks.push(t);
  const layout = baseLayout({
    margin: { l: 40, r: 10, t: 34, b: 16 },
    title: { text: 'θi in degrees (0 = the normal; + toward the viewer, − toward the mirror direction)', font: { size: 11 }, x: 0.02, xanchor: 'left', y: 0.98 },
    showlegend: true,
    legend: { x: 1, xanchor: 'right', y: 1, yanchor: 'top', font: { size: 10 }, bgcolor: 'rgba(255,255,255,0.8)' },
    polar: {
      // Counted clockwise from the normal at the top: the viewer's side is
      // the right, the mirror direction the left.
      sector: full ? [0, 360] : [0, 180],
      domain: { x: [0, 0.72], y: [0, 1] },
      angularaxis: {
        rotation: 90,
        direction: 'clockwise',
        thetaunit: 'degrees',
        tickmode: 'array',
        tickvals: ticks,
        ticktext: ticks.map((t) => `${t}°`),
      },
      radialaxis: {
        type: log ? 'log' : 'linear',
        title: { text: 'f·|cos θi|, pdf (1/sr)' },
        exponentformat: 'power',
        // Log: five decades below the peak (a pdf's far tail would squeeze the rest).
        ...(log && rMax > 0 ? { range: [Math.log10(rMax) - 5, Math.log10(rMax) + 0.05], dtick: full ? 2 : 1 } : {}),
      },
    },
    uirevision: `polar-${log ? 'log' : 'linear'}`,
  });
  return Plotly.react('polar', traces, layout, PLOT_CONFIG);
}

// --- #lobe3d: the active material's lobe as a surface ----------------------

VIEW_FUNCTIONS.lobe3d = async function viewLobe(ctx) {
  const { snap } = ctx;
  await guard(ctx);
  const a = activeOf(snap);
  const data = await ctx.api('api/lobe', { material: a.desc, theta_o: snap.thetaO, phi_o: snap.phiO });
  await drawLobe(snap, a, data);
  ctx.drawn();
};

function drawLobe(snap, a, data) {
  const Plotly = plotlyReady();
  const thetas = (data.theta_deg || []).map(radians);
  const phis = (data.phi_deg || []).map(radians);
  const rows = Array.isArray(data.values) ? data.values : [];
  const X = []; const Y = []; const Z = []; const C = []; const T = [];
  let vmax = 0;
  thetas.forEach((t, i) => {
    const row = rows[i] || [];
    const st = Math.sin(t); const ct = Math.cos(t);
    const xr = []; const yr = []; const zr = []; const cr = []; const tr = [];
    phis.forEach((p, j) => {
      const v = row[j];
      if (!isNum(v)) {
        xr.push(null); yr.push(null); zr.push(null); cr.push(null); tr.push('');
        return;
      }
      // The point value·direction: the lobe's shape.
      xr.push(v * st * Math.cos(p));
      yr.push(v * st * Math.sin(p));
      zr.push(v * ct);
      cr.push(v);
      tr.push(`θ ${fmt(data.theta_deg[i])}°, φ ${fmt(data.phi_deg[j])}°: ${fmt(v, 4)}`);
      if (v > vmax) vmax = v;
    });
    X.push(xr); Y.push(yr); Z.push(zr); C.push(cr); T.push(tr);
  });
  const L = vmax > 0 ? vmax * 1.15 : 1;
  const to = radians(snap.thetaO); const po = radians(snap.phiO);
  const wo = [Math.sin(to) * Math.cos(po), Math.sin(to) * Math.sin(po), Math.cos(to)];
  const traces = [
    {
      type: 'surface',
      name: a.name,
      x: X, y: Y, z: Z,
      surfacecolor: C,
      text: T,
      cmin: 0,
      cmax: vmax > 0 ? vmax : 1,
      colorscale: 'Viridis',
      colorbar: { title: { text: 'f·|cos θ|<br>(1/sr)' }, thickness: 12, len: 0.7 },
      hovertemplate: 'f·|cos θ| at %{text}<extra></extra>',
      lighting: { ambient: 0.75, diffuse: 0.6, specular: 0.1 },
    },
    {
      type: 'scatter3d', mode: 'lines', name: 'viewer ωo',
      x: [0, wo[0] * L], y: [0, wo[1] * L], z: [0, wo[2] * L],
      line: { color: '#d62728', width: 5 }, hoverinfo: 'name',
    },
    {
      type: 'scatter3d', mode: 'lines', name: 'normal',
      x: [0, 0], y: [0, 0], z: [data.sphere ? -L : 0, L],
      line: { color: '#888888', width: 3 }, hoverinfo: 'name',
    },
  ];
  const axis = (text) => ({ title: { text }, zeroline: false, showspikes: false });
  const layout = baseLayout({
    margin: { l: 0, r: 0, t: 10, b: 0 },
    showlegend: false,
    scene: {
      xaxis: axis('x (1/sr)'),
      yaxis: axis('y (1/sr)'),
      zaxis: axis('z, normal (1/sr)'),
      aspectmode: 'data',
      camera: { eye: { x: 1.4, y: -1.6, z: 0.9 }, up: { x: 0, y: 0, z: 1 } },
    },
    // The same uirevision each time: the camera the user turned stays.
    uirevision: 'lobe',
  });
  return Plotly.react('lobe3d', traces, layout, PLOT_CONFIG);
}

// --- #albedo: every material's albedo against θo ---------------------------

VIEW_FUNCTIONS.albedo = async function viewAlbedo(ctx) {
  const { snap } = ctx;
  const results = await perMaterial(ctx, 'api/albedo', snap.materials, { phi_o: snap.phiO });
  const { ok, error } = splitResults(results);
  await drawAlbedo(snap, ok);
  ctx.drawn();
  return error;
};

function drawAlbedo(snap, results) {
  const Plotly = plotlyReady();
  const traces = [];
  let xMax = 90;
  for (const { e, data } of results) {
    const x = data.theta_deg || [];
    const rgb = Array.isArray(data.albedo) ? data.albedo : [];
    xMax = Math.max(xMax, maxOf(x));
    const isActive = e.index === snap.active;
    traces.push({
      type: 'scatter', mode: 'lines', name: e.name,
      x, y: rgb.map(luminance),
      line: { color: e.colour, width: isActive ? 2.5 : 1.5 },
      hovertemplate: 'θo %{x:.1f}°: %{y:.4g}<extra>%{fullData.name}</extra>',
    });
    if (isActive) {
      ['R', 'G', 'B'].forEach((channel, k) => {
        traces.push({
          type: 'scatter', mode: 'lines', name: `${e.index + 1}. ${channel}`, showlegend: false,
          x, y: rgb.map((c) => (Array.isArray(c) && isNum(c[k]) ? c[k] : luminance(c))),
          line: { color: RGB_COLOURS[k], width: 1, dash: 'dot' },
          hovertemplate: `θo %{x:.1f}°: ${channel} %{y:.4g}<extra>%{fullData.name}</extra>`,
        });
      });
    }
  }
  const layout = baseLayout({
    showlegend: true,
    // Room above the plot for the legend, left of the mode bar.
    margin: { l: 55, r: 15, t: 34, b: 45 },
    legend: {
      orientation: 'h', x: 0, y: 1.0, yanchor: 'bottom', font: { size: 10 },
      entrywidth: 0.5, entrywidthmode: 'fraction',
    },
    xaxis: { title: { text: 'θo (degrees)' }, range: [0, xMax > 90 ? 180 : 90], dtick: 15, zeroline: false },
    yaxis: { title: { text: 'directional albedo' }, rangemode: 'tozero' },
    // The current θo.
    shapes: [{
      type: 'line', xref: 'x', yref: 'paper', x0: snap.thetaO, x1: snap.thetaO, y0: 0, y1: 1,
      line: { color: '#555555', width: 1, dash: 'dot' },
    }],
    annotations: [{
      x: snap.thetaO, xref: 'x', y: 1, yref: 'paper', yanchor: 'top', xanchor: 'left',
      text: ' θo', showarrow: false, font: { size: 10, color: '#555555' },
    }, {
      x: 1, xref: 'paper', y: 0.01, yref: 'paper', xanchor: 'right', yanchor: 'bottom',
      text: 'dotted: R, G, B of the active material', showarrow: false, font: { size: 9.5, color: '#777777' },
    }],
    uirevision: 'albedo',
  });
  return Plotly.react('albedo', traces, layout, PLOT_CONFIG);
}

// --- #sphere: the active material's lit sphere, progressive ----------------

/** The running sum of the passes, and how many. */
const sphereAcc = { sum: null, passes: 0, width: 0, height: 0 };

/** What the sphere's picture depends on. */
function sphereKey(snap) {
  return descriptionKey({ material: activeOf(snap).desc, env: snap.env });
}

VIEW_FUNCTIONS.sphere = async function viewSphere(ctx) {
  const { snap } = ctx;
  const base = { material: activeOf(snap).desc, env: snap.env, size: SPHERE_SIZE };
  let sum = null;
  let width = 0;
  let height = 0;
  for (let pass = 0; pass < SPHERE_PASSES; pass += 1) {
    const data = await ctx.api('api/sphere', { ...base, pass });
    const w = Math.max(0, Math.floor(data.width)) || 0;
    const ht = Math.max(0, Math.floor(data.height)) || 0;
    const rgb = Array.isArray(data.rgb) ? data.rgb : [];
    if (!sum || w !== width || ht !== height) {
      width = w; height = ht;
      sum = new Float64Array(width * height * 3);
    }
    for (let i = 0; i < sum.length; i += 1) {
      const v = rgb[i];
      if (v > 0 && v < Infinity) sum[i] += v; // null, NaN and negatives add nothing
    }
    sphereAcc.sum = sum;
    sphereAcc.width = width;
    sphereAcc.height = height;
    sphereAcc.passes = pass + 1;
    drawSphere();
    ctx.drawn();
  }
};

/** sRGB bytes of linear values in [0, 1], looked up. */
const SRGB_LUT = (() => {
  const n = 4096;
  const lut = new Uint8ClampedArray(n + 1);
  for (let i = 0; i <= n; i += 1) lut[i] = Math.round(255 * srgbEncode(i / n));
  return lut;
})();

/** Tone-map the running mean (exposure, clamp, sRGB) onto the canvas. */
function drawSphere() {
  const { sum, passes, width, height } = sphereAcc;
  const canvas = $('#sphere');
  if (!sum || !passes || !width || !height) return;
  if (canvas.width !== width) canvas.width = width;
  if (canvas.height !== height) canvas.height = height;
  const g = canvas.getContext('2d');
  const image = g.createImageData(width, height);
  const px = image.data;
  const scale = Math.pow(2, state.exposure) / passes;
  const n = SRGB_LUT.length - 1;
  for (let i = 0, j = 0; i < width * height; i += 1, j += 3) {
    for (let c = 0; c < 3; c += 1) {
      const v = sum[j + c] * scale;
      px[4 * i + c] = v >= 1 ? 255 : SRGB_LUT[Math.round(v * n)];
    }
    px[4 * i + 3] = 255;
  }
  g.putImageData(image, 0, 0);
  $('#sphere-info').textContent = `${width}×${height}, pass ${passes} of ${SPHERE_PASSES}`
    + `${passes < SPHERE_PASSES ? '…' : ''}, exposure ${state.exposure >= 0 ? '+' : ''}${state.exposure} EV`;
}

// --- #warp: Nori's warp test of the chosen strategy ------------------------

VIEW_FUNCTIONS.warp = async function viewWarp(ctx) {
  const { snap } = ctx;
  const info = await guard(ctx, { needInfo: true });
  const strategy = setStrategies(info.strategies);
  if (!strategy) {
    await drawWarpEmpty('no sampling strategy applies to this material (a delta lobe)');
    ctx.drawn();
    return null;
  }
  const a = activeOf(snap);
  const data = await ctx.api('api/warp', {
    material: a.desc, strategy, theta_o: snap.thetaO, phi_o: snap.phiO,
  });
  await drawWarp(data, strategy);
  ctx.drawn();
  return null;
};

/**
 * The flat grid(s) of the projected disk as a heatmap: res×res row-major,
 * row 0 at y = −1; with `sphere` the lower hemisphere's grid follows the
 * upper's and is drawn to its right, a gap between.
 */
function diskGrid(flat, n, sphere) {
  const values = Array.isArray(flat) ? flat : [];
  const cell = 2 / n;
  const gap = sphere ? Math.max(1, Math.round(n / 8)) : 0;
  const columns = sphere ? 2 * n + gap : n;
  const x = Array.from({ length: columns }, (_, k) => -1 + (k + 0.5) * cell);
  const y = Array.from({ length: n }, (_, k) => -1 + (k + 0.5) * cell);
  const z = [];
  for (let r = 0; r < n; r += 1) {
    const row = values.slice(r * n, r * n + n).map((v) => (isNum(v) ? v : null));
    while (row.length < n) row.push(null);
    if (sphere) {
      for (let k = 0; k < gap; k += 1) row.push(null);
      const lower = values.slice(n * n + r * n, n * n + r * n + n).map((v) => (isNum(v) ? v : null));
      while (lower.length < n) lower.push(null);
      row.push(...lower);
    }
    z.push(row);
  }
  const shift = 2 + gap * cell; // the lower disk's x offset
  const tickvals = sphere ? [-1, 0, 1, shift - 1, shift, shift + 1] : [-1, -0.5, 0, 0.5, 1];
  const ticktext = sphere ? ['−1', '0', '1', '−1', '0', '1'] : ['−1', '−0.5', '0', '0.5', '1'];
  return { x, y, z, tickvals, ticktext, shift, sphere };
}

function diskLayout(title, grid) {
  return baseLayout({
    title: { text: title, font: { size: 12 }, y: 0.97 },
    margin: { l: 40, r: 6, t: 28, b: 38 },
    xaxis: {
      // Over the sphere: the upper hemisphere's disk, then the lower's.
      title: { text: grid.sphere ? 'x = sin θ cos φ (upper | lower)' : 'x = sin θ cos φ' },
      tickvals: grid.tickvals, ticktext: grid.ticktext, tickangle: 0,
      zeroline: false, showgrid: false, constrain: 'domain',
    },
    yaxis: {
      title: { text: 'y = sin θ sin φ', standoff: 6 }, zeroline: false, showgrid: false,
      scaleanchor: 'x', scaleratio: 1, constrain: 'domain', automargin: true,
    },
    uirevision: 'warp',
  });
}

async function drawWarp(data, strategy) {
  const Plotly = plotlyReady();
  const n = Math.max(1, Math.floor(data.res) || 1);
  const sphere = Boolean(data.sphere);
  const observed = diskGrid(data.observed, n, sphere);
  const expected = diskGrid(data.expected, n, sphere);
  // One colour scale for both (Nori's warp test).
  const zmax = Math.max(maxOf(data.observed), maxOf(data.expected)) || 1;
  const counts = (grid) => ({
    type: 'heatmap', x: grid.x, y: grid.y, z: grid.z, zmin: 0, zmax,
    colorscale: 'Viridis', hoverongaps: false,
    colorbar: { title: { text: 'samples', side: 'right' }, thickness: 8, len: 0.8 },
    hovertemplate: 'x %{x:.2f}, y %{y:.2f}: %{z:.1f}<extra></extra>',
  });
  const m = Math.max(1, Math.floor(data.heat_res) || n);
  const weights = diskGrid(Array.isArray(data.weights) ? data.weights : [], m, sphere);
  const weightTrace = {
    type: 'heatmap', x: weights.x, y: weights.y, z: weights.z,
    colorscale: 'Cividis', hoverongaps: false,
    colorbar: { title: { text: 'f·cos/pdf', side: 'right' }, thickness: 8, len: 0.8 },
    hovertemplate: 'x %{x:.2f}, y %{y:.2f}: %{z:.4g}<extra></extra>',
  };
  await Promise.all([
    Plotly.react('warp-observed', [counts(observed)], diskLayout(`observed (${strategy})`, observed), WARP_CONFIG),
    Plotly.react('warp-expected', [counts(expected)], diskLayout('expected (from the pdf)', expected), WARP_CONFIG),
    Plotly.react('warp-weights', [weightTrace], diskLayout('weight f·cos θ / pdf', weights), WARP_CONFIG),
  ]);
  renderChi2(data.chi2, strategy);
}

/** The χ² test's outcome: statistic, degrees of freedom, p-value, pass/fail. */
function renderChi2(chi2, strategy) {
  const el = $('#chi2');
  if (!chi2 || typeof chi2 !== 'object') {
    el.className = '';
    el.textContent = 'no χ² result';
    return;
  }
  el.className = chi2.passes ? 'pass' : 'fail';
  el.replaceChildren(h('span', {},
    h('strong', {}, chi2.passes ? 'passes' : 'fails'),
    ` χ² test of ${strategy}: p-value ${fmt(chi2.p_value, 3)}`
      + ` (statistic ${fmt(chi2.statistic, 4)}, ${fmt(chi2.dof, 6)} degrees of freedom)`,
    chi2.message ? h('div', { class: 'chi2-message' }, chi2.message) : null));
}

async function drawWarpEmpty(message) {
  const Plotly = plotlyReady();
  const empty = { x: [], y: [], z: [], tickvals: [-1, 0, 1], ticktext: ['−1', '0', '1'], sphere: false };
  await Promise.all(['warp-observed', 'warp-expected', 'warp-weights'].map((id) => Plotly.react(
    id, [], diskLayout(id.replace('warp-', ''), empty), WARP_CONFIG,
  )));
  const el = $('#chi2');
  el.className = '';
  el.textContent = message;
}

// --- #estimate: each strategy's estimate at this direction -----------------

VIEW_FUNCTIONS.estimate = async function viewEstimate(ctx) {
  const { snap } = ctx;
  await guard(ctx);
  const a = activeOf(snap);
  const data = await ctx.api('api/estimate', { material: a.desc, theta_o: snap.thetaO, phi_o: snap.phiO });
  renderEstimate(snap, a, data);
  ctx.drawn();
};

function renderEstimate(snap, a, data) {
  const rgb = (c) => (Array.isArray(c) ? c.map((v) => fmt(v, 4)).join(', ') : fmt(c, 4));
  const rows = Array.isArray(data.rows) ? data.rows : [];
  let best = -Infinity;
  for (const r of rows) if (isNum(r.efficiency) && r.efficiency > best) best = r.efficiency;
  const head = h('tr', {},
    h('th', {}, 'strategy'),
    h('th', { class: 'num', title: 'the estimate of the reflected radiance, per channel' }, 'mean (R, G, B)'),
    h('th', { class: 'num', title: 'relative error of the mean\'s luminance against the reference' }, 'relative error'),
    h('th', { class: 'num', title: 'per-sample variance of the luminance of f·L·cos/pdf' }, 'variance'),
    h('th', { class: 'num', title: 'the variance of uniform sampling over this strategy\'s' }, 'variance reduction'),
    h('th', { class: 'num', title: 'time the estimate took' }, 'time'),
    h('th', { class: 'num', title: '1 / (variance × time): higher is better' }, 'efficiency (1/s)'));
  const reference = h('tr', { class: 'reference' },
    h('td', {}, 'reference'), h('td', { class: 'num' }, rgb(data.reference)),
    h('td', { class: 'num' }, '—'), h('td', { class: 'num' }, '—'), h('td', { class: 'num' }, '—'),
    h('td', { class: 'num' }, '—'), h('td', { class: 'num' }, '—'));
  const body = h('tbody', {}, reference, ...rows.map((r) => {
    const strategy = state.strategies.get(r.name);
    const unreliable = r.variance_reliable === false;
    return h('tr', { class: isNum(r.efficiency) && r.efficiency === best ? 'best' : null },
      h('td', { title: strategy && strategy.description ? strategy.description : null }, r.name),
      h('td', { class: 'num' }, rgb(r.mean)),
      h('td', { class: 'num' }, fmt(r.relative_error, 3)),
      h('td', {
        class: `num${unreliable ? ' unreliable' : ''}`,
        title: unreliable ? 'unreliable: the estimate misses the reference (the strategy seldom samples where the integrand lives)' : null,
      }, `${fmt(r.variance, 4)}${unreliable ? ' ?' : ''}`),
      h('td', { class: 'num' }, isNum(r.variance_reduction) ? `${fmt(r.variance_reduction, 3)}×` : '—'),
      h('td', { class: 'num' }, isNum(r.time_s) ? `${fmt(r.time_s * 1e3, 3)} ms` : '—'),
      h('td', { class: 'num' }, fmt(r.efficiency, 4)));
  }));
  const caption = h('p', { class: 'estimate-caption' },
    `${a.name} at θo = ${snap.thetaO}°, φo = ${snap.phiO}°`
      + `${data.light ? `, light ${data.light}` : ''}${isNum(data.samples) ? `, ${data.samples} samples a strategy` : ''}`
      + '; the most efficient strategy is highlighted.');
  const table = h('table', { class: 'estimates' }, h('thead', {}, head), body);
  $('#estimate').replaceChildren(caption, table);
  if (!rows.length) $('#estimate').append(h('p', { class: 'status' }, 'No strategy applies (a delta lobe).'));
}

// ---------------------------------------------------------------------------
// 6. The material panels and their parameter controls
// ---------------------------------------------------------------------------

/** Call `fn` on both input and change (handlers compare, so twice is harmless). */
function onEdit(el, fn) {
  el.addEventListener('input', fn);
  el.addEventListener('change', fn);
}

/** Redraw the whole list (after adding, removing, changing a model...). */
function renderMaterials() {
  $('#materials').replaceChildren(...state.materials.map((m, i) => materialPanel(m, i)));
  updateDataButtons();
}

/** Redraw one panel (after a reset). */
function rerenderPanel(m) {
  const i = state.materials.indexOf(m);
  const old = $('#materials').children[i];
  if (old) old.replaceWith(materialPanel(m, i));
}

/** Something in material `m` changed: the views that show it ask again. */
function materialChanged(m) {
  const isActive = state.materials.indexOf(m) === state.active;
  updateDataButtons();
  changed(isActive ? ALL_VIEWS : ['polar', 'albedo']);
}

/** Set (or, back at the default, remove) param P of material m. */
function setParam(m, P, value) {
  const before = descriptionKey(describe(m));
  if (P.default !== undefined && P.default !== null && sameValue(P, value, P.default)) {
    delete m.values[P.name];
  } else {
    m.values[P.name] = canonical(P, value);
  }
  if (descriptionKey(describe(m)) !== before) materialChanged(m);
}

function setActive(m) {
  const i = state.materials.indexOf(m);
  if (i < 0 || i === state.active) return;
  state.active = i;
  document.querySelectorAll('#materials .material').forEach((el, k) => {
    el.classList.toggle('active', k === i);
    const radio = el.querySelector('.active-radio');
    if (radio) radio.checked = k === i;
  });
  updateDataButtons();
  changed();
}

function addMaterial() {
  const source = state.materials[state.active];
  const description = source ? describe(source) : (state.models.values().next().value || {}).example;
  const m = materialFromDescription(description || { type: modelNames()[0] });
  state.materials.push(m);
  state.active = state.materials.length - 1;
  renderMaterials();
  changed();
}

function removeMaterial(m) {
  const i = state.materials.indexOf(m);
  if (i < 0 || state.materials.length <= 1) return;
  state.materials.splice(i, 1);
  if (state.active > i) state.active -= 1;
  else if (state.active === i) state.active = Math.min(i, state.materials.length - 1);
  renderMaterials();
  changed();
}

/**
 * Switch material m to model `type`: start from the model's example and
 * keep the params of the same name and kind the user had set (alpha, say).
 */
function changeModel(m, type) {
  if (type === m.type) return;
  const model = state.models.get(type);
  if (!model) return;
  const fresh = materialFromDescription(model.example || { type }, { colour: m.colour });
  const oldParams = new Map(paramsOf(m).map((P) => [P.name, P]));
  const values = fresh.values;
  for (const P of model.params) {
    const old = oldParams.get(P.name);
    if (!old || old.kind !== P.kind || !hasOwn(m.values, P.name)) continue;
    const v = m.values[P.name];
    if (P.kind === 'number' && !(isNum(v) && (!isNum(P.min) || v >= P.min) && (!isNum(P.max) || v <= P.max))) continue;
    if ((P.kind === 'choice' || P.kind === 'file') && Array.isArray(P.choices) && P.choices.length && !P.choices.includes(v)) continue;
    if (sameValue(P, v, P.default)) delete values[P.name];
    else values[P.name] = v;
  }
  m.type = type;
  m.values = values;
  m.label = null;
  m.note = null;
  renderMaterials();
  materialChanged(m);
}

/** One material's panel: header (active, colour, model, two-sided, remove), params. */
function materialPanel(m, index) {
  const isActive = index === state.active;
  const panel = h('div', {
    class: `material${isActive ? ' active' : ''}`,
    'data-index': index,
    'data-uid': m.uid,
    style: `--material-colour: ${m.colour}`,
  });

  const radio = h('input', {
    type: 'radio', name: 'active-material', class: 'active-radio',
    title: 'make this the active material', 'aria-label': `make material ${index + 1} active`,
  });
  radio.checked = isActive;
  onEdit(radio, () => { if (radio.checked) setActive(m); });

  const swatch = h('span', { class: 'swatch', title: 'this material\'s colour in the plots', style: `background: ${m.colour}` });

  const model = modelOf(m);
  const select = h('select', { class: 'model', title: model && model.doc ? model.doc : 'model', 'aria-label': 'model' });
  const names = modelNames();
  if (!names.includes(m.type)) names.unshift(m.type);
  for (const n of names) {
    const info = state.models.get(n);
    // A model the server gives no example of (measured, with no data
    // files) cannot be built: offered, but disabled.
    const unusable = Boolean(info) && info.example === null && n !== m.type;
    select.append(h('option', {
      value: n,
      disabled: unusable,
      title: unusable ? 'needs a data file (start lobe explore with --data DIR)' : (info && info.doc ? info.doc : null),
    }, n));
  }
  select.value = m.type;
  onEdit(select, () => changeModel(m, select.value));

  const twosided = h('input', { type: 'checkbox', class: 'twosided' });
  twosided.checked = m.twosided;
  onEdit(twosided, () => {
    if (m.twosided === twosided.checked) return;
    m.twosided = twosided.checked;
    materialChanged(m);
  });

  const remove = h('button', {
    type: 'button', class: 'remove', title: 'remove this material',
    'aria-label': `remove material ${index + 1}`, disabled: state.materials.length <= 1,
  }, '×');
  remove.addEventListener('click', (event) => {
    event.stopPropagation();
    removeMaterial(m);
  });

  panel.append(h('div', { class: 'material-head' },
    radio, swatch, h('span', { class: 'material-number' }, `${index + 1}`), select,
    h('label', { class: 'twosided-label', title: 'wrap as {"type": "twosided", "bsdf": …}' }, twosided, 'two-sided'),
    remove));
  if (m.label || m.note) panel.append(h('div', { class: 'material-note' }, m.note || m.label));
  if (model && model.doc) panel.append(h('div', { class: 'material-doc' }, model.doc));
  panel.append(h('div', { class: 'params' }, ...paramsOf(m).map((P) => paramControl(m, P))));

  // A click anywhere else on the panel makes it active.
  panel.addEventListener('click', (event) => {
    if (!event.target.closest('input, select, button, label, textarea, output')) setActive(m);
  });
  return panel;
}

/** The default of P as text (for titles and unset controls). */
function defaultText(P) {
  if (P.default === undefined || P.default === null) return 'auto';
  if (typeof P.default === 'string') return P.default.replace(/`/g, '');
  return typeof P.default === 'number' ? fmt(P.default, 4) : JSON.stringify(P.default);
}

/** The control row of param P of material m. */
function paramControl(m, P) {
  const set = hasOwn(m.values, P.name);
  const current = set ? m.values[P.name] : P.default;
  const row = h('div', {
    class: `param param-${P.kind || 'other'}${set ? ' set' : ''}`,
    title: `${P.meaning || P.name} (default: ${defaultText(P)})`,
  });
  const reset = h('button', {
    type: 'button', class: 'reset', title: `back to the default (${defaultText(P)})`,
    'aria-label': `reset ${P.name}`,
  }, '↺');
  reset.hidden = !set;
  reset.addEventListener('click', () => {
    if (!hasOwn(m.values, P.name)) return;
    delete m.values[P.name];
    rerenderPanel(m);
    materialChanged(m);
  });
  const apply = (value) => {
    setParam(m, P, value);
    const nowSet = hasOwn(m.values, P.name);
    reset.hidden = !nowSet;
    row.classList.toggle('set', nowSet);
  };
  let control;
  if (isObjectChoice(P, current)) {
    control = objectChoiceControl(P, current, apply);
  } else if (set && !fitsKind(P, current)) {
    // A value the control cannot show (a fit's nested object, say): as JSON.
    control = jsonControl(P, current, apply);
  } else {
    switch (P.kind) {
      case 'number': control = numberControl(P, current, apply); break;
      case 'colour': control = colourControl(P, current, apply); break;
      case 'bool': control = boolControl(P, current, apply); break;
      case 'choice':
      case 'file': control = choiceControl(P, current, apply); break;
      case 'ior': control = iorControl(P, current, apply); break;
      default: control = jsonControl(P, current, apply);
    }
  }
  row.append(h('span', { class: 'param-name' }, P.name), control, reset);
  return row;
}

/**
 * How a number slider maps to values: linear over [min, max], or with
 * P.log a position 0–1000 over [min, max] logarithmically. Missing or
 * infinite bounds get workable ones.
 */
function sliderScale(P, current) {
  const log = Boolean(P.log);
  let lo = isNum(P.min) ? P.min : 0;
  let hi = isNum(P.max) ? P.max : NaN;
  if (log) {
    if (!(lo > 0)) lo = hi > 0 ? hi * 1e-4 : 1e-4;
    if (!(hi > lo)) hi = lo * 1e4;
    const a = Math.log(lo);
    const b = Math.log(hi);
    return {
      lo, hi, min: 0, max: 1000, step: 1,
      toPos: (v) => Math.round((1000 * (Math.log(clamp(v, lo, hi)) - a)) / (b - a)),
      fromPos: (p) => clamp(round3(Math.exp(a + ((b - a) * p) / 1000)), lo, hi),
    };
  }
  if (!(hi > lo)) {
    hi = Math.max(lo + 1, isNum(current) ? current * 2 : 0, isNum(P.default) ? P.default * 4 : 0);
  }
  return {
    lo, hi, min: lo, max: hi, step: 'any',
    toPos: (v) => clamp(v, lo, hi),
    fromPos: (p) => clamp(round3(p), lo, hi),
  };
}

/** A number: a range slider (data-param) with its value shown. */
function numberControl(P, current, apply) {
  const scale = sliderScale(P, current);
  const input = h('input', {
    type: 'range', 'data-param': P.name, min: scale.min, max: scale.max, step: scale.step,
    'aria-label': P.name, 'data-log': P.log ? 'true' : null,
  });
  const value = isNum(current) ? current : null;
  input.value = String(scale.toPos(value === null ? scale.lo : value));
  input.dataset.value = value === null ? '' : String(value);
  const out = h('output', { class: 'value' }, value === null ? `(${defaultText(P)})` : fmt(value, 4));
  onEdit(input, () => {
    const v = scale.fromPos(Number(input.value));
    input.dataset.value = String(v);
    out.textContent = fmt(v, 4);
    apply(v);
  });
  return h('span', { class: 'control number' }, input, out);
}

/**
 * A colour: R, G, B sliders (data-param, data-channel 0–2) over [0, max].
 * While "grey" is ticked only the first shows and it sets all three (the
 * value is then one number); unticked, the three move on their own.
 */
function colourControl(P, current, apply) {
  const given = colourArray(current);
  let rgb = given || [0, 0, 0];
  // The server's span, widened to show a larger current value (a fit's η).
  const hi = Math.max(isNum(P.max) && P.max > 0 ? P.max : 10, ...rgb);
  const grey = h('input', {
    type: 'checkbox', class: 'grey', 'data-param': P.name, 'data-channel': 'grey',
    'aria-label': `${P.name}: one grey value`,
  });
  grey.checked = !given || (rgb[0] === rgb[1] && rgb[1] === rgb[2]);
  const preview = h('span', { class: 'colour-preview', title: 'the colour (sRGB)' });
  const sliders = [];
  const outs = [];
  const lines = [];
  let hasValue = false; // set by the user since the panel was drawn
  const sync = () => {
    sliders.forEach((s, k) => {
      s.value = String(rgb[k]);
      outs[k].textContent = given || hasValue ? fmt(rgb[k], 3) : `(${defaultText(P)})`;
    });
    if (isNum(P.max) && P.max > 0 && (given || hasValue)) {
      const bytes = rgb.map((v) => Math.round(255 * srgbEncode(v / hi)));
      preview.style.background = `rgb(${bytes.join(', ')})`;
    }
    // Grey: one slider for the three channels; else R, G, B tinted.
    sliders.forEach((s, k) => { s.style.accentColor = grey.checked ? '' : RGB_COLOURS[k]; });
    lines.forEach((line, k) => { line.hidden = grey.checked && k > 0; });
  };
  const grid = h('span', { class: 'channels' });
  ['R', 'G', 'B'].forEach((name, k) => {
    const s = h('input', {
      type: 'range', 'data-param': P.name, 'data-channel': k, min: 0, max: hi, step: 'any',
      'aria-label': `${P.name} ${name}`,
    });
    const o = h('output', { class: 'value' });
    onEdit(s, () => {
      const v = clamp(round3(Number(s.value)), 0, hi);
      rgb = grey.checked ? [v, v, v] : rgb.map((c, i) => (i === k ? v : c));
      hasValue = true;
      sync();
      apply(grey.checked ? v : rgb.slice());
    });
    sliders.push(s);
    outs.push(o);
    // First column: the grey checkbox (first line), the colour (second).
    const first = k === 0 ? h('span', { class: 'channel', title: 'grey: one value for R, G and B' }, grey)
      : h('span', { class: 'channel' }, k === 1 ? preview : null);
    const line = h('span', { class: 'channel-line', title: grey.checked ? null : name }, first, s, o);
    lines.push(line);
    grid.append(line);
  });
  onEdit(grey, () => {
    if (grey.checked && (given || hasValue)) {
      const g = round3((rgb[0] + rgb[1] + rgb[2]) / 3);
      const change = !rgb.every((c) => c === g);
      rgb = [g, g, g];
      sync();
      if (change) apply(g);
    } else {
      sync();
    }
  });
  sync();
  return h('span', { class: 'control colour' }, grid);
}

function boolControl(P, current, apply) {
  const input = h('input', { type: 'checkbox', 'data-param': P.name, 'aria-label': P.name });
  input.checked = current === true;
  onEdit(input, () => apply(input.checked));
  return h('span', { class: 'control bool' }, input);
}

/** The names a choice or file param offers (files: the measured data files). */
function choicesOf(P, current) {
  let choices = Array.isArray(P.choices) ? P.choices.map(String) : [];
  if (P.kind === 'file' && !choices.length) {
    choices = state.dataFiles.filter((f) => f.kind === 'measured').map((f) => f.path);
  }
  if (typeof current === 'string' && current && !choices.includes(current)
    && !(P.kind === 'file' && current === P.default)) {
    choices = [current, ...choices];
  }
  return choices;
}

/** Can P's usual control show `v`? */
function fitsKind(P, v) {
  switch (P.kind) {
    case 'number': return isNum(v);
    case 'colour': return colourArray(v) !== null;
    case 'bool': return typeof v === 'boolean';
    case 'choice':
    case 'file': return typeof v === 'string';
    case 'ior': return isNum(v) || typeof v === 'string';
    default: return true;
  }
}

/**
 * A choice written as an object {"type": name, ...}: a Fresnel term
 * (`fresnel` of cook-torrance and conductor, which the library reads as
 * {"type": "schlick", "f0": …}), or any choice whose value is such an object.
 */
function isObjectChoice(P, v) {
  if (P.kind !== 'choice') return false;
  return P.name === 'fresnel' || Boolean(v && typeof v === 'object' && !Array.isArray(v) && typeof v.type === 'string');
}

/**
 * An object choice: a select of its "type" (data-param) and, when the
 * object has more than its type (a fit's f0, η, k), that object as JSON.
 */
function objectChoiceControl(P, current, apply) {
  const value = current && typeof current === 'object' ? current : { type: String(current || '') };
  const choices = Array.isArray(P.choices) ? P.choices.map(String) : [];
  if (value.type && !choices.includes(value.type)) choices.unshift(value.type);
  const select = h('select', { 'data-param': P.name, 'aria-label': P.name });
  for (const c of choices) select.append(h('option', { value: c }, c));
  select.value = value.type || '';
  const details = Object.keys(value).length > 1;
  const text = h('input', {
    type: 'text', class: 'object-json', 'data-param': P.name, spellcheck: 'false',
    'aria-label': `${P.name} as JSON`, title: 'the whole value as JSON',
  });
  text.value = JSON.stringify(value);
  text.hidden = !details;
  onEdit(select, () => {
    if (!select.value || select.value === value.type) return;
    apply({ type: select.value });
  });
  text.addEventListener('change', () => {
    try {
      const v = JSON.parse(text.value);
      text.classList.remove('invalid');
      if (v && typeof v === 'object') apply(v);
    } catch {
      text.classList.add('invalid');
    }
  });
  return h('span', { class: 'control choice object-choice' }, select, text);
}

/** A choice or a data file: a select (data-param). */
function choiceControl(P, current, apply) {
  const choices = choicesOf(P, current);
  const select = h('select', { 'data-param': P.name, 'aria-label': P.name });
  if (!choices.includes(current)) {
    select.append(h('option', { value: '', disabled: true }, `(${defaultText(P)})`));
  }
  for (const c of choices) select.append(h('option', { value: c }, c));
  select.value = choices.includes(current) ? current : '';
  onEdit(select, () => { if (select.value) apply(select.value); });
  return h('span', { class: 'control choice' }, select);
}

/** An index of refraction: a named one from a select, or a number typed in. */
function iorControl(P, current, apply) {
  const NUMBER = '__number';
  const choices = Array.isArray(P.choices) ? P.choices.map(String) : [];
  if (typeof current === 'string' && current && !choices.includes(current)) choices.unshift(current);
  const select = h('select', { 'data-param': P.name, 'aria-label': P.name });
  for (const c of choices) select.append(h('option', { value: c }, c));
  select.append(h('option', { value: NUMBER }, 'number…'));
  const number = h('input', {
    type: 'number', class: 'ior-number', 'data-param': P.name, min: '0.01', max: '10', step: '0.001',
    'aria-label': `${P.name} as a number`,
  });
  if (isNum(current)) {
    select.value = NUMBER;
    number.value = String(current);
  } else {
    select.value = choices.includes(current) ? current : NUMBER;
    number.value = '1.5';
    number.hidden = select.value !== NUMBER;
  }
  onEdit(select, () => {
    if (select.value === NUMBER) {
      number.hidden = false;
      const v = Number(number.value);
      apply(isNum(v) && v > 0 ? v : 1.5);
    } else {
      number.hidden = true;
      apply(select.value);
    }
  });
  onEdit(number, () => {
    const v = Number(number.value);
    if (number.value !== '' && isNum(v) && v > 0) apply(v);
  });
  return h('span', { class: 'control ior' }, select, number);
}

/** Any other kind: the value as JSON text (a bare word is taken as a string). */
function jsonControl(P, current, apply) {
  const input = h('input', {
    type: 'text', 'data-param': P.name, 'aria-label': P.name, spellcheck: 'false',
    placeholder: defaultText(P),
  });
  input.value = current === undefined || current === null || current === P.default ? '' : JSON.stringify(current);
  input.addEventListener('change', () => {
    const text = input.value.trim();
    if (!text) return;
    let v;
    try { v = JSON.parse(text); } catch { v = text; }
    apply(v);
  });
  return h('span', { class: 'control other' }, input);
}

// ---------------------------------------------------------------------------
// 7. Global controls, the data panel, start-up
// ---------------------------------------------------------------------------

function showAngles() {
  $('#theta-o-value').textContent = `${state.thetaO}°`;
  $('#phi-o-value').textContent = `${state.phiO}°`;
}

function bindGlobalControls() {
  const theta = $('#theta-o');
  onEdit(theta, () => {
    let v = Number(theta.value);
    if (!isNum(v)) return;
    if (v === 90) {
      // The horizon has no view direction: step over it.
      v = state.thetaO < 90 ? 91 : 89;
      theta.value = String(v);
    }
    if (v === state.thetaO) return;
    state.thetaO = v;
    showAngles();
    changed();
  });
  const phi = $('#phi-o');
  onEdit(phi, () => {
    const v = Number(phi.value);
    if (!isNum(v) || v === state.phiO) return;
    state.phiO = v;
    showAngles();
    changed();
  });
  const log = $('#polar-log');
  onEdit(log, () => {
    if (log.checked === state.polarLog) return;
    state.polarLog = log.checked;
    changed(['polar']);
  });
  const strategy = $('#warp-strategy');
  onEdit(strategy, () => {
    const v = strategy.value || null;
    if (v === state.warpStrategy) return;
    state.warpStrategy = v;
    changed(['warp'], { soon: true });
  });
  const env = $('#env');
  onEdit(env, () => {
    if (env.value === state.env) return;
    state.env = env.value;
    changed(['sphere']);
  });
  const exposure = $('#exposure');
  onEdit(exposure, () => {
    const v = Number(exposure.value);
    if (!isNum(v) || v === state.exposure) return;
    state.exposure = v;
    $('#exposure-value').textContent = `${v >= 0 ? '+' : ''}${v} EV`;
    drawSphere(); // the same passes, tone-mapped again: no new request
  });
  $('#add-material').addEventListener('click', addMaterial);
  $('#load-data').addEventListener('click', loadData);
  $('#fit').addEventListener('click', fitActive);
  for (const f of ['json', 'toml', 'python']) {
    $(`#copy-${f}`).addEventListener('click', () => { copyDescription(f); });
  }
  $('#error').addEventListener('click', () => {
    $('#error').hidden = true;
    errorOwner = null;
  });
}

/** Fill #data-file (measured files) and #env (sky and the envmaps). */
function setupDataPanel(t0) {
  const measured = state.dataFiles.filter((f) => f.kind === 'measured').map((f) => f.path);
  const select = $('#data-file');
  select.replaceChildren(...measured.map((p) => h('option', { value: p }, p)));
  if (!measured.length) select.append(h('option', { value: '' }, 'no measured files'));
  select.disabled = !measured.length;
  $('#load-data').disabled = !measured.length || !measuredModel();

  const env = $('#env');
  const maps = state.dataFiles.filter((f) => f.kind === 'envmap').map((f) => f.path);
  env.replaceChildren(h('option', { value: 'sky' }, 'sky'), ...maps.map((p) => h('option', { value: p }, p)));
  env.value = state.env;

  bumpData(t0);
}

/** #data was redrawn with server data (the file list, a fit). */
function bumpData(t0) {
  const el = $('#data');
  el.dataset.version = String(Number(el.dataset.version || 0) + 1);
  el.dataset.ms = String(Math.round(performance.now() - t0));
}

/** #fit only for a measured active material. */
function updateDataButtons() {
  const m = state.materials[state.active];
  const file = m ? fileOf(m) : null;
  const fit = $('#fit');
  fit.disabled = !file || fitController !== null;
  fit.title = file
    ? `fit an analytic model to ${file} and add it beside the active material`
    : 'make a measured material active to fit it';
}

/** Add a measured material with the chosen file, and make it active. */
function loadData() {
  const file = $('#data-file').value;
  const mm = measuredModel();
  if (!file || !mm) return;
  const m = materialFromDescription({ ...(mm.model.example || {}), type: mm.model.name, [mm.param.name]: file });
  state.materials.push(m);
  state.active = state.materials.length - 1;
  renderMaterials();
  changed();
}

/** Fit the active measured material's file; add the fit right after it. */
async function fitActive() {
  const t0 = performance.now();
  const m = state.materials[state.active];
  const file = m ? fileOf(m) : null;
  const status = $('#fit-status');
  if (!file) {
    showError('make a measured material active to fit it', 'fit', false);
    return;
  }
  if (fitController) fitController.abort();
  const controller = new AbortController();
  fitController = controller;
  updateDataButtons();
  status.textContent = 'fitting…';
  const distribution = $('#fit-distribution').value;
  const body = distribution ? { file, distribution } : { file };
  try {
    const data = await api('api/fit', body, controller.signal);
    const short = file.split('/').pop();
    const fitted = materialFromDescription(data.material, {
      label: `fit of ${short}`,
      note: `fit of ${file}${distribution ? ` (${distribution})` : ''}: error ${fmt(data.error, 4)}`,
    });
    const at = state.materials.indexOf(m);
    state.materials.splice(at < 0 ? state.materials.length : at + 1, 0, fitted);
    if (at >= 0 && state.active > at) state.active += 1;
    status.textContent = `error ${fmt(data.error, 4)}`;
    renderMaterials();
    bumpData(t0);
    clearError('fit');
    changed(['polar', 'albedo']);
  } catch (err) {
    status.textContent = isAbort(err) ? '' : 'failed';
    reportFailure(err, 'fit');
  } finally {
    if (fitController === controller) fitController = null;
    updateDataButtons();
  }
}

/** Normalise one param of api/models (the fields the controls read). */
function normaliseParam(P) {
  return {
    ...P,
    name: String(P.name),
    kind: P.kind || 'other',
    choices: Array.isArray(P.choices) ? P.choices : [],
  };
}

/**
 * The starting materials: the server's (`initial`, its --material list),
 * else two of the page's own, filled up from the models' examples.
 */
function initialMaterials(initial) {
  state.materials = [];
  const given = (Array.isArray(initial) ? initial : []).filter((d) => d && typeof d === 'object' && d.type);
  const wanted = given.length ? given
    : [{ type: 'roughconductor', alpha: 0.2 }, { type: 'roughplastic', alpha: 0.3 }];
  for (const d of wanted) {
    const inner = d.type === 'twosided' && d.bsdf ? d.bsdf : d;
    if (given.length || state.models.has(inner.type)) state.materials.push(materialFromDescription(d));
  }
  for (const name of modelNames()) {
    if (given.length || state.materials.length >= 2) break;
    if (state.materials.some((m) => m.type === name)) continue;
    const model = state.models.get(name);
    state.materials.push(materialFromDescription(model.example || { type: name }));
  }
  state.active = 0;
}

async function init() {
  const t0 = performance.now();
  bindGlobalControls();
  showAngles();
  if (!window.Plotly) showError('Plotly did not load (vendor/plotly.min.js): the plots cannot be drawn', 'plotly', false);
  let data;
  try {
    data = await api('api/models');
  } catch (err) {
    reportFailure(err, 'models');
    return;
  }
  for (const model of Array.isArray(data.models) ? data.models : []) {
    state.models.set(model.name, {
      ...model,
      params: (Array.isArray(model.params) ? model.params : []).map(normaliseParam),
    });
  }
  state.strategies = new Map((Array.isArray(data.strategies) ? data.strategies : []).map((s) => [s.name, s]));
  state.dataFiles = Array.isArray(data.data_files) ? data.data_files : [];
  initialMaterials(data.initial);
  setupDataPanel(t0);
  if (!state.materials.length) {
    showError('the server lists no models', 'models', false);
    return;
  }
  renderMaterials();
  changed();
  lastInput = t0; // the first draw's data-ms counts from the page's start
}

if (document.readyState === 'loading') {
  document.addEventListener('DOMContentLoaded', () => { init().catch((err) => reportFailure(err, 'init')); });
} else {
  init().catch((err) => reportFailure(err, 'init'));
}
