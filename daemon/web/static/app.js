'use strict';
// atelier's web page: the job list, one job, the machines; all live from /api/events.
// Plain ES2020, no framework, no build step. Server data (job names, reasons, details) only
// ever reaches the DOM as text or attribute values, never as markup: it is user data.

const PAGE_SIZE = 50;
const STATES = ['queued', 'converting', 'ready', 'running', 'completed', 'failed', 'canceled', 'interrupted'];
const ACTIVE = new Set(['queued', 'converting', 'ready', 'running']);   // elapsed still grows
const COUNTING = new Set(['converting', 'running']);                     // time left shrinks
// What machine each kind's jobs go to ("knitting", "laser", "files" or "none"), from the
// daemon's registry of kinds (GET /api/status "kind_machines"): the page names no kind itself.
const machineOf = (kind) => (app.status && app.status.kind_machines && app.status.kind_machines[kind]) || 'none';
const knits = (kind) => machineOf(kind) === 'knitting';
const COLUMNS = { id: 'Job', name: 'Name', kind: 'Kind', state: 'State', progress: 'Progress',
  elapsed: 'Elapsed', left: 'Time left', device: 'Device', reason: 'Reason' };

const app = {
  session: null,      // GET /api/session
  status: null,       // GET /api/status
  devices: [],        // GET /api/devices, then every `devices` event
  route: { page: '', id: null, query: {} },
  seq: 0,             // bumped on each navigation: answers for an older page are dropped
  list: null,         // jobs page: {state, kind, offset, total, recs: Map id -> rec}
  job: null,          // job page: rec of the job with its show fields
  jobKeys: {},        // job page: what the previews/actions were built from (rebuild on change)
  actionMsg: null,    // job page: {id, text, error}
  liveLost: false,    // the event stream failed: refetch when it opens again
  listHash: '#/jobs', // the list as last shown (filter, page): where a job page leads back to
};

// ---------------------------------------------------------------- small helpers

const $ = (sel, root = document) => root.querySelector(sel);

// el('a', {href, class, text, dataset, onclick}, ...children): attributes via setAttribute,
// text via text nodes. There is deliberately no way to pass markup or a style attribute.
function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (v == null || v === false) continue;
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k === 'dataset') Object.assign(e.dataset, v);
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v === true ? '' : String(v));
  }
  for (const c of children.flat()) if (c != null && c !== false) e.append(c instanceof Node ? c : String(c));
  return e;
}

const pad = (n) => String(n).padStart(2, '0');

function parseJson(text) {
  try { return text ? JSON.parse(text) : null; } catch (e) { return null; }
}

// When a server error has no JSON body (a proxy, or the connection cut short), say what the
// status means rather than a bare number.
const STATUS_TEXT = { 401: 'not logged in', 403: 'refused (log in again?)', 404: 'not found',
  409: 'not allowed in this state', 413: 'the file is larger than the daemon accepts (413)',
  429: 'too many logins from here: wait a minute', 503: 'the daemon is busy: try again' };

async function api(path, { method = 'GET', body, form, act = false } = {}) {
  const headers = act && app.session && app.session.csrf ? { 'X-Atelier-CSRF': app.session.csrf } : {};
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const payload = form || (body !== undefined ? JSON.stringify(body) : undefined);
  let res;
  try {
    res = await fetch(path, { method, headers, body: payload, credentials: 'same-origin', cache: 'no-store' });
  } catch (e) {
    throw Object.assign(new Error('cannot reach atelierd (connection failed)'), { status: 0 });
  }
  const data = parseJson(await res.text().catch(() => ''));
  if (!res.ok) {
    const msg = data && typeof data.error === 'string' ? data.error
      : STATUS_TEXT[res.status] || `${res.status} ${res.statusText || 'error'}`;
    throw Object.assign(new Error(msg), { status: res.status });
  }
  return data;
}

// ---------------------------------------------------------------- formatting

function fmtDuration(s) {
  if (s == null || !Number.isFinite(s)) return '—';
  s = Math.max(0, Math.round(s));
  if (s < 60) return `${s} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${pad(s % 60)} s`;
  const h = Math.floor(s / 3600);
  if (h < 48) return `${h} h ${pad(Math.floor((s % 3600) / 60))} min`;
  return `${Math.floor(h / 24)} d ${pad(h % 24)} h`;
}

// ISO 8601 UTC -> local "2026-12-07 22:31:05"
function fmtTime(iso) {
  const d = new Date(iso);
  if (!iso || Number.isNaN(d.getTime())) return iso || '';
  return `${d.getFullYear()}-${pad(d.getMonth() + 1)}-${pad(d.getDate())} ` +
    `${pad(d.getHours())}:${pad(d.getMinutes())}:${pad(d.getSeconds())}`;
}

function progressText(p) {
  if (!p || !(p.total > 0)) return '—';
  return p.unit === 'percent' || !p.unit ? `${Math.round((p.done * 100) / p.total)} %` : `${p.done}/${p.total} ${p.unit}`;
}

const badge = (state) => el('span', { class: `badge s-${state}`, text: state });

// A div bar rather than <progress>: it takes the state's colour, and "nothing counted yet"
// stays an empty bar instead of an indeterminate animation.
function progressEl(p, state) {
  const total = p && p.total > 0 ? p.total : 0;
  const done = total ? Math.min(Math.max(p.done || 0, 0), total) : 0;
  // A completed job whose machine counts nothing (stitch files written to a folder) is done.
  const whole = !total && state === 'completed';
  const fill = el('div', { class: 'fill' });
  fill.style.width = whole ? '100%' : total ? `${(done * 100) / total}%` : '0%';
  const text = whole ? 'done' : progressText(p);
  return el('div', { class: `progress s-${state}` },
    el('div', { class: 'bar', role: 'progressbar', 'aria-valuemin': 0, 'aria-valuemax': total || 100,
      'aria-valuenow': done, 'aria-valuetext': text }, fill),
    el('span', { class: 'ptext', text }));
}

const jobLink = (id, text) => el('a', { href: `#/jobs/${encodeURIComponent(id)}`, text: text == null ? String(id) : text });

// ---------------------------------------------------------------- job records and clocks

// A job with the moments its elapsed_s and time_left_s were read, so the page can count on
// between server updates. An event's job may lack elapsed_s, state_s, time_left_s: they go on
// from the values known.
function mergeJob(rec, j) {
  const now = Date.now();
  const job = { ...(rec ? rec.job : {}), ...j };
  const out = { job, te: now, tl: rec ? rec.tl : now };
  if (typeof j.elapsed_s !== 'number') {
    job.elapsed_s = rec ? elapsedOf(rec) : Math.max(0, (now - Date.parse(job.created)) / 1000) || 0;
  }
  if (typeof j.state_s !== 'number' && rec) {
    job.state_s = rec.job.state !== job.state ? 0 : (rec.job.state_s || 0) + (now - rec.te) / 1000;
  }
  if ('time_left_s' in j) out.tl = now;
  else if (!COUNTING.has(job.state)) job.time_left_s = null;
  return out;
}

function elapsedOf(rec) {
  return (rec.job.elapsed_s || 0) + (ACTIVE.has(rec.job.state) ? (Date.now() - rec.te) / 1000 : 0);
}

function leftOf(rec) {
  const t = rec.job.time_left_s;
  return t == null || !COUNTING.has(rec.job.state) ? t : Math.max(0, t - (Date.now() - rec.tl) / 1000);
}

// ---------------------------------------------------------------- routing

function parseHash() {
  const [path, qs = ''] = location.hash.replace(/^#\/?/, '').split('?');
  const parts = path.split('/').filter(Boolean);
  const query = Object.fromEntries(new URLSearchParams(qs));
  if (parts[0] === 'machines') return { page: 'machines', id: null, query };
  if (parts[0] === 'jobs' && /^\d+$/.test(parts[1] || '')) return { page: 'job', id: parts[1], query };
  return { page: 'jobs', id: null, query };
}

function jobsHash(state, kind, page) {
  const q = new URLSearchParams(Object.entries({ state, kind, page: page > 1 ? page : '' }).filter(([, v]) => v));
  return `#/jobs${[...q].length ? `?${q}` : ''}`;
}

function route() {
  const prev = app.route;
  app.route = parseHash();
  app.seq++;
  const page = app.route.page;
  for (const [id, p] of [['nav-jobs', 'jobs'], ['nav-machines', 'machines']]) {
    const a = document.getElementById(id);
    if (p === page || (p === 'jobs' && page === 'job')) a.setAttribute('aria-current', 'page');
    else a.removeAttribute('aria-current');
  }
  if (page === 'jobs') showJobs(prev.page === 'jobs');
  else if (page === 'job') showJob(prev.page === 'job' && prev.id === app.route.id);
  else showMachines();
}

// The current page's data again (after a reconnect of the event stream).
function refreshPage() {
  ({ jobs: loadJobs, job: loadJob, machines: loadDevices })[app.route.page]();
}

// ---------------------------------------------------------------- header: status and login

async function loadStatus() {
  app.status = await api('/api/status').catch((e) => ({ error: e.message }));
  if (Array.isArray(app.status.devices) && !app.devices.length) app.devices = app.status.devices;
  renderStatus();
  fillKindSelects();
}

let statusTimer = 0;
// Queue counts change with every state change; a burst of them asks for one status.
function scheduleStatus() {
  if (!statusTimer) statusTimer = setTimeout(() => { statusTimer = 0; loadStatus(); }, 150);
}

function renderStatus() {
  const box = $('#status-text');
  const s = app.status;
  if (!s) return;
  if (s.error) { box.replaceChildren(el('span', { class: 'error', text: s.error })); return; }
  const parts = [el('span', { class: 'version', text: `atelierd ${s.version || ''}`.trim() })];
  const queue = s.queue || {};
  const counts = STATES.filter((st) => queue[st] > 0);  // each a link to the list of that state
  for (const st of counts) parts.push(' · ', el('a', { href: jobsHash(st, '', 1), class: `count s-${st}`, text: `${queue[st]} ${st}` }));
  if (!counts.length) parts.push(' · no jobs');
  if (document.body.dataset.live !== '1') parts.push(' · ', el('span', { class: 'offline', text: 'not live' }));
  box.replaceChildren(...parts);
}

async function loadSession() {
  app.session = await api('/api/session').catch(() => ({ can_act: false, logins: {} }));
  sessionChanged();
}

const canAct = () => !!(app.session && app.session.can_act);

function sessionChanged() {
  renderLogin();
  updateUploadEnabled();
  if (app.route.page === 'job' && app.job) renderJobActions();
}

const hasLogins = () => !!(app.session && app.session.logins &&
  (app.session.logins.password || app.session.logins.token));
// What a page says where it cannot act.
const actNote = () => (hasLogins() ? 'log in to upload/act' : 'read-only: no logins configured');

function renderLogin() {
  const s = app.session;
  const area = $('#login-area');
  const user = el('span', { class: 'user', text: s.user || 'token' });
  if (s.can_act && s.auth === 'session') {
    area.replaceChildren(user, ' · ', el('button', { id: 'logout', type: 'button', class: 'link', text: 'Log out', onclick: logout }));
  } else if (s.can_act) {
    area.replaceChildren(user);  // a bearer token: nothing to log out of
  } else if (hasLogins()) {
    area.replaceChildren(el('button', { id: 'login-open', type: 'button', text: 'Log in', 'aria-controls': 'login-panel',
      'aria-expanded': 'false', onclick: () => toggleLogin() }));
  } else {
    area.replaceChildren(el('span', { class: 'muted', text: 'read-only', title: 'no logins configured ([web] token, [web.users])' }));
  }
  if (s.can_act) toggleLogin(false);
}

function toggleLogin(show) {
  const panel = $('#login-panel');
  const logins = (app.session && app.session.logins) || {};
  panel.hidden = show === undefined ? !panel.hidden : !show;
  $('#login-password-fields').hidden = !logins.password;
  $('#login-token-fields').hidden = !logins.token;
  $('#login-token-label').textContent = logins.password ? 'or a token' : 'Token';
  const opener = $('#login-open');
  if (opener) opener.setAttribute('aria-expanded', String(!panel.hidden));
  if (!panel.hidden) {
    loginMessage('');
    (logins.password ? $('#login-user') : $('#login-token')).focus();
  }
}

function loginMessage(text, error) {
  $('#login-message').textContent = text;
  $('#login-message').className = `message${error ? ' error' : ''}`;
}

async function submitLogin(ev) {
  ev.preventDefault();
  const token = $('#login-token').value.trim();
  const logins = (app.session && app.session.logins) || {};
  const body = token && logins.token ? { token }
    : { user: $('#login-user').value.trim(), password: $('#login-password').value };
  if (!body.token && !body.user) { loginMessage('enter a user and password, or a token', true); return; }
  $('#login-submit').disabled = true;
  loginMessage('logging in…');
  try {
    app.session = await api('/api/login', { method: 'POST', body });  // the new session, its csrf
    $('#login-password').value = $('#login-token').value = '';
    toggleLogin(false);
    sessionChanged();
  } catch (e) {
    loginMessage(e.message, true);
  } finally {
    $('#login-submit').disabled = false;
  }
}

async function logout() {
  await api('/api/logout', { method: 'POST', act: true }).catch(() => {});  // the new session tells
  await loadSession();
}

// ---------------------------------------------------------------- jobs page

function showJobs(samePage) {
  if (!samePage || !$('#jobs-page')) buildJobsPage();
  app.listHash = location.hash || '#/jobs';
  const q = app.route.query;
  setSelect($('#filter-state'), q.state || '');
  setSelect($('#filter-kind'), q.kind || '');
  syncUploadKind();
  loadJobs();
}

// Select a value even before its option exists (kinds arrive with /api/status).
function setSelect(sel, value) {
  if (value && ![...sel.options].some((o) => o.value === value)) sel.append(el('option', { value, text: value }));
  sel.value = value;
}

function buildJobsPage() {
  const stateSel = el('select', { id: 'filter-state', onchange: filterChanged },
    el('option', { value: '', text: 'all states' }), STATES.map((s) => el('option', { value: s, text: s })));
  const kindSel = el('select', { id: 'filter-kind', class: 'kind-select', onchange: filterChanged },
    el('option', { value: '', text: 'all kinds' }));
  const table = el('table', { class: 'jobs' },
    el('thead', {}, el('tr', {}, Object.entries(COLUMNS).map(([k, v]) => el('th', { class: `c-${k}`, scope: 'col', text: v })))),
    el('tbody', { id: 'jobs-body' }));
  $('#app').replaceChildren(el('section', { id: 'jobs-page', class: 'page' },
    buildUpload(),
    el('div', { class: 'toolbar' },
      el('div', { class: 'filters' }, el('label', {}, 'State ', stateSel), el('label', {}, 'Kind ', kindSel)),
      el('div', { class: 'paging' },
        el('button', { id: 'page-newer', type: 'button', text: '‹ Newer', onclick: () => goPage(-1) }),
        el('span', { id: 'jobs-total', 'aria-live': 'polite' }),
        el('button', { id: 'page-older', type: 'button', text: 'Older ›', onclick: () => goPage(1) }))),
    el('div', { class: 'table-wrap' }, table)));
  fillKindSelects();
  updateUploadEnabled();
}

const filterChanged = () => { location.hash = jobsHash($('#filter-state').value, $('#filter-kind').value, 1); };

function goPage(delta) {
  const q = app.route.query;
  const page = Math.max(1, (parseInt(q.page, 10) || 1) + delta);
  location.hash = jobsHash(q.state || '', q.kind || '', page);
}

// Both the kind filter and the upload's kind list come from /api/status "kinds".
function fillKindSelects() {
  const kinds = (app.status && app.status.kinds) || [];
  for (const sel of document.querySelectorAll('select.kind-select')) {
    const have = new Set([...sel.options].map((o) => o.value));
    for (const k of kinds) if (!have.has(k)) sel.append(el('option', { value: k, text: k }));
  }
  syncUploadKind();
}

// The upload's kind follows the kind filter until it is chosen by hand.
function syncUploadKind() {
  const up = $('#upload-kind');
  const k = app.route.query.kind;
  if (up && !up.dataset.touched && k && [...up.options].some((o) => o.value === k)) up.value = k;
}

async function loadJobs() {
  const seq = app.seq;
  const q = app.route.query;
  const offset = (Math.max(1, parseInt(q.page, 10) || 1) - 1) * PAGE_SIZE;
  const params = new URLSearchParams({ ...(q.state && { state: q.state }), ...(q.kind && { kind: q.kind }),
    limit: PAGE_SIZE, offset });
  $('#jobs-page').classList.add('loading');
  try {
    const data = await api(`/api/jobs?${params}`);
    if (seq !== app.seq) return;
    app.list = { state: q.state || '', kind: q.kind || '', offset: data.offset ?? offset,
      total: data.total ?? 0, recs: new Map() };
    const recs = (data.jobs || []).map((j) => mergeJob(null, j));
    for (const rec of recs) app.list.recs.set(String(rec.job.id), rec);
    $('#jobs-body').replaceChildren(...(recs.length ? recs.map(jobRow)
      : [messageRow(offset ? 'no jobs on this page' : 'no jobs')]));
  } catch (e) {
    if (seq !== app.seq) return;
    app.list = null;
    $('#jobs-body').replaceChildren(messageRow(e.message, true));
  } finally {
    if (seq === app.seq) $('#jobs-page').classList.remove('loading');
  }
  updateTotal();
}

const messageRow = (text, error) => el('tr', { class: 'empty' },
  el('td', { colspan: Object.keys(COLUMNS).length, class: error ? 'error' : 'muted', text }));

function updateTotal() {
  const L = app.list;
  const rows = document.querySelectorAll('#jobs-body tr[data-job-id]:not(.left-filter)').length;
  const { total, offset } = L || { total: 0, offset: 0 };
  $('#jobs-total').textContent = rows ? `${offset + 1}–${offset + rows} of ${total}` : `0 of ${total}`;
  $('#page-newer').disabled = offset <= 0;
  $('#page-older').disabled = !L || offset + PAGE_SIZE >= total;
}

const jobRow = (rec) => fillRow(el('tr', { dataset: { jobId: rec.job.id } }), rec);
const cell = (col, ...kids) => el('td', { class: `c-${col}`, 'data-label': COLUMNS[col] }, ...kids);

function fillRow(tr, rec) {
  const j = rec.job;
  tr.dataset.state = j.state;
  tr.replaceChildren(
    cell('id', jobLink(j.id)),
    cell('name', jobLink(j.id, j.name || '(no name)'), el('div', { class: 'sub', text: fmtTime(j.created) })),
    cell('kind', j.kind),
    cell('state', badge(j.state)),
    cell('progress', progressEl(j.progress, j.state)),
    cell('elapsed', fmtDuration(elapsedOf(rec))),
    cell('left', fmtDuration(leftOf(rec))),
    cell('device', j.device || '—'),
    cell('reason', j.reason || ''));
  return tr;
}

const matchesList = (j, L) => (!L.state || j.state === L.state) && (!L.kind || j.kind === L.kind);

// A job event on the list: update its row in place, or put a job that now belongs on page 1
// (a new one, or one that entered the state filter) where it sorts, newest (highest id) first.
function listEvent(ev) {
  const L = app.list;
  const j = ev.job;
  const id = String(j.id);
  const tbody = $('#jobs-body');
  const old = L.recs.get(id);
  if (old) {
    const rec = mergeJob(old, j);
    L.recs.set(id, rec);
    const tr = tbody.querySelector(`tr[data-job-id="${CSS.escape(id)}"]`);
    if (tr) {
      fillRow(tr, rec);
      if (!ev.progress && ev.from !== ev.to) flash(tr);
      // It stays on the page (rows never jump away), dimmed once it no longer matches.
      const left = !matchesList(j, L);
      if (left !== tr.classList.contains('left-filter')) L.total += left ? -1 : 1;
      tr.classList.toggle('left-filter', left);
      updateTotal();
    }
    return;
  }
  const entered = !ev.from || (L.state && ev.from !== L.state);
  if (ev.progress || !matchesList(j, L) || !entered) return;
  L.total++;
  if (L.offset === 0) insertRow(tbody, mergeJob(null, j));
  updateTotal();
}

function insertRow(tbody, rec) {
  const L = app.list;
  const rows = [...tbody.querySelectorAll('tr[data-job-id]')];
  const before = rows.find((r) => Number(r.dataset.jobId) < Number(rec.job.id));
  if (!before && rows.length >= PAGE_SIZE) return;           // older than the whole page
  const tr = jobRow(rec);
  L.recs.set(String(rec.job.id), rec);
  const empty = tbody.querySelector('tr.empty');
  if (empty) empty.remove();
  tbody.insertBefore(tr, before || null);
  flash(tr);
  const all = tbody.querySelectorAll('tr[data-job-id]');
  if (all.length > PAGE_SIZE) {                               // keep the page at its size
    const last = all[all.length - 1];
    L.recs.delete(last.dataset.jobId);
    last.remove();
  }
}

function flash(node) {
  node.classList.remove('flash');
  void node.offsetWidth;  // a reflow restarts the animation
  node.classList.add('flash');
}

// ---------------------------------------------------------------- upload

function buildUpload() {
  const file = el('input', { type: 'file', id: 'upload-file', class: 'visually-hidden', onchange: fileChosen });
  const zone = el('label', { class: 'dropzone', id: 'dropzone', for: 'upload-file' },
    el('span', { class: 'drop-title', text: 'Drop a file here' }),
    el('span', { class: 'drop-sub', text: 'or tap to choose one' }),
    el('span', { id: 'upload-file-name', class: 'file-name' }));
  for (const t of ['dragenter', 'dragover']) {
    zone.addEventListener(t, (e) => { e.preventDefault(); if (canAct()) zone.classList.add('over'); });
  }
  zone.addEventListener('dragleave', () => zone.classList.remove('over'));
  zone.addEventListener('drop', fileDropped);
  return el('form', { id: 'upload-form', class: 'upload card', onsubmit: submitUpload },
    el('h2', { class: 'card-title', text: 'New job' }),
    el('div', { class: 'upload-grid' },
      el('div', { class: 'upload-file' }, file, zone),
      el('div', { class: 'upload-fields' },
        el('label', { for: 'upload-kind', text: 'Kind' }),
        el('select', { id: 'upload-kind', name: 'kind', class: 'kind-select',
          onchange: (e) => { e.target.dataset.touched = '1'; } }),
        el('label', { for: 'upload-sets', text: 'Settings' }),
        el('textarea', { id: 'upload-sets', name: 'set', rows: 2, spellcheck: 'false',
          placeholder: 'optional, one key=value a line, e.g. width=100' }),
        el('div', { class: 'upload-actions' },
          el('button', { id: 'upload-submit', type: 'submit', class: 'primary', text: 'Upload' }),
          el('span', { id: 'upload-note', class: 'note' })))),
    el('p', { id: 'upload-message', class: 'message', role: 'status', 'aria-live': 'polite' }));
}

function updateUploadEnabled() {
  const form = $('#upload-form');
  if (!form) return;
  const ok = canAct();
  for (const id of ['upload-file', 'upload-kind', 'upload-sets', 'upload-submit']) document.getElementById(id).disabled = !ok;
  form.classList.toggle('disabled', !ok);
  $('#upload-note').textContent = ok ? '' : actNote();
}

const fileChosen = () => showFileName($('#upload-file').files[0]);

function showFileName(f) {
  const size = f && (f.size < 1048576 ? `${Math.ceil(f.size / 1024)} KiB` : `${(f.size / 1048576).toFixed(1)} MiB`);
  $('#upload-file-name').textContent = f ? `${f.name} (${size})` : '';
}

function fileDropped(e) {
  e.preventDefault();
  $('#dropzone').classList.remove('over');
  if (!canAct()) { uploadMessage(actNote(), true); return; }
  const files = e.dataTransfer && e.dataTransfer.files;
  if (!files || !files.length) return;
  $('#upload-file').files = files;  // the form then sends it as if chosen
  showFileName(files[0]);
  uploadMessage('');
}

function uploadMessage(text, error, ...extra) {
  const m = $('#upload-message');
  m.className = `message${error ? ' error' : ''}`;
  m.replaceChildren(text, ...extra);
}

async function submitUpload(ev) {
  ev.preventDefault();
  const f = $('#upload-file').files[0];
  const kind = $('#upload-kind').value;
  if (!f || !kind) { uploadMessage(f ? 'choose the kind of job' : 'choose or drop a file first', true); return; }
  const limit = app.session && app.session.max_upload_bytes;
  if (limit && f.size > limit) {
    uploadMessage(`${f.name}: ${f.size} bytes is larger than the hot folder's limit of ${limit} bytes ` +
      '([limits] max_file_bytes)', true);
    return;
  }
  // Small fields before the file, so a streaming server knows the kind before the bytes.
  const form = new FormData();
  form.append('kind', kind);
  for (const raw of $('#upload-sets').value.split('\n')) {
    const line = raw.trim();
    if (!line || line.startsWith('#')) continue;
    if (!/^[^=\s]+\s*=/.test(line)) { uploadMessage(`settings: "${line}" is not key=value`, true); return; }
    form.append('set', line);
  }
  form.append('file', f, f.name);
  const button = $('#upload-submit');
  button.disabled = true;
  uploadMessage(`uploading ${f.name}…`);
  try {
    const job = await api('/api/submit', { method: 'POST', form, act: true });
    uploadMessage('job ', false, jobLink(job.id), ` ${job.state || 'queued'}`);
    $('#upload-file').value = '';   // kind and settings stay for the next file
    fileChosen();
    if (document.body.dataset.live !== '1' && app.route.page === 'jobs') loadJobs();  // no event will
  } catch (e) {
    // A connection cut mid-upload is most often the daemon refusing a file over its limit.
    const hint = e.status === 0 ? ' (the daemon may have refused a file over its [limits] max_file_bytes)' : '';
    uploadMessage(`upload failed: ${e.message}${hint}`, true);
    if (e.status === 401 || e.status === 403) loadSession();
  } finally {
    button.disabled = !canAct();
  }
}

// ---------------------------------------------------------------- one job

function showJob(sameJob) {
  if (sameJob && $('#job-page')) { loadJob(); return; }
  const id = app.route.id;
  app.job = null;
  app.jobKeys = {};
  if (!app.actionMsg || app.actionMsg.id !== id) app.actionMsg = null;
  // Fixed containers, filled by renderJob: live updates touch only the parts that changed.
  const slot = (sid, cls) => el('div', { id: sid, class: cls });
  $('#app').replaceChildren(el('section', { id: 'job-page', class: 'page', dataset: { jobId: id } },
    el('p', { class: 'back' }, el('a', { href: app.listHash, text: '‹ all jobs' })),
    slot('job-head', 'job-head'),
    slot('job-progress', 'job-progress'),
    el('p', { id: 'job-reason', class: 'reason' }),
    el('div', { id: 'job-actions', class: 'actions' }),
    el('p', { id: 'action-message', class: 'message', role: 'status', 'aria-live': 'polite' }),
    slot('job-warnings', ''),
    slot('job-previews', 'previews'),
    slot('job-outputs', ''),
    slot('job-history', '')));
  setActionMessage();
  loadJob();
}

async function loadJob() {
  const seq = app.seq;
  const id = app.route.id;
  if (app.route.page !== 'job' || !id) return;  // a timer set on a job page that was left
  try {
    const data = await api(`/api/jobs/${encodeURIComponent(id)}`);
    if (seq !== app.seq) return;
    app.job = mergeJob(null, data);
    renderJob();
  } catch (e) {
    if (seq !== app.seq) return;
    $('#job-head').replaceChildren(el('h1', { text: `Job ${id}` }),
      el('p', { class: 'error', text: e.status === 404 ? `no job ${id}` : e.message }));
  }
}

let jobReloadTimer = 0;
const scheduleJobReload = () => { clearTimeout(jobReloadTimer); jobReloadTimer = setTimeout(loadJob, 250); };
const deviceOf = (job) => app.devices.find((d) => d.name === job.device) || null;

// A laser job: its device is a grbl one; without a known device, a grbl device takes its kind;
// with no device list at all, a laser kind; and while the kinds are not known yet, any job (so
// a laser start is never left unconfirmed).
function isLaser(job) {
  const d = deviceOf(job);
  if (d) return d.driver === 'grbl';
  const takers = app.devices.filter((x) => Array.isArray(x.kinds) && x.kinds.includes(job.kind));
  if (takers.length) return takers.some((x) => x.driver === 'grbl');
  return !(app.status && app.status.kind_machines) || machineOf(job.kind) === 'laser';
}

function renderJob() {
  const j = app.job.job;
  $('#job-page').dataset.state = j.state;
  document.title = `${j.id} ${j.name || ''} · atelier`;
  const row = (dt, ...dd) => [el('dt', { text: dt }), el('dd', {}, ...dd)];
  $('#job-head').replaceChildren(
    el('h1', {}, el('span', { class: 'job-id', text: `Job ${j.id}` }), ' ', el('span', { class: 'job-name', text: j.name || '' })),
    el('dl', { class: 'facts' },
      row('State', badge(j.state), j.state_s != null ? el('span', { id: 'job-state-for', class: 'sub' }) : null),
      row('Kind', j.kind),
      row('Device', el('span', { id: 'job-device' })),
      row('Created', fmtTime(j.created)),
      row('Updated', fmtTime(j.updated)),
      row('Elapsed', el('span', { id: 'job-elapsed', text: fmtDuration(elapsedOf(app.job)) })),
      row('Time left', el('span', { id: 'job-left', text: fmtDuration(leftOf(app.job)) })),
      j.estimated_s != null ? row('Estimated', fmtDuration(j.estimated_s)) : null,
      j.output_dir ? row('Output folder', el('code', { text: j.output_dir })) : null));
  tick();
  renderJobLive();
  renderJobDevice();
  renderJobActions();
  renderWarnings(j.warnings || []);
  renderPreviews(j);
  renderOutputs(j);
  renderHistory(j.history || []);
  setActionMessage();  // shown or hidden as the job's state now says
}

// The parts a progress step changes.
function renderJobLive() {
  const j = app.job.job;
  $('#job-progress').replaceChildren(progressEl(j.progress, j.state));
  $('#job-reason').textContent = j.reason || '';
  $('#job-left').textContent = fmtDuration(leftOf(app.job));
}

function renderJobDevice() {
  const box = $('#job-device');
  if (!box || !app.job) return;
  const j = app.job.job;
  if (!j.device) { box.replaceChildren('—'); return; }
  const d = deviceOf(j);
  if (!d) { box.replaceChildren(j.device); return; }
  // The device's detail speaks of its current job: show it here only when that is this job.
  const other = d.job && String(d.job.id) !== String(j.id);
  box.replaceChildren(el('a', { href: '#/machines', text: d.name }), ` (${d.driver}${d.port ? `, ${d.port}` : ''}) `,
    el('span', { class: `dstate d-${d.state}`, text: d.state }),
    other ? el('span', { class: 'device-detail' }, 'busy with job ', jobLink(d.job.id), ` ${d.job.name || ''}`)
      : d.detail ? el('span', { class: `device-detail${WAITING.test(d.detail) ? ' prompt' : ''}`, text: d.detail }) : '');
}

function jobActions(j) {
  const laser = isLaser(j);
  switch (j.state) {
    case 'ready': return laser ? ['start', 'frame', 'cancel'] : ['start', 'cancel'];
    case 'queued': case 'converting': return ['cancel'];
    case 'running': return laser ? ['hold', 'resume', 'cancel'] : ['cancel'];
    case 'failed': case 'canceled': return ['retry'];
    case 'interrupted': return knits(j.kind) ? ['resume', 'retry'] : ['retry'];
    default: return [];
  }
}

const ACTION_LABELS = { start: 'Start', frame: 'Frame (beam off)', cancel: 'Cancel job', hold: 'Hold',
  resume: 'Resume', retry: 'Retry' };

// Rebuilt only when the set of actions changes, so a row number being typed survives updates.
function renderJobActions() {
  const j = app.job.job;
  const actions = jobActions(j);
  const fromRow = j.state === 'interrupted' && knits(j.kind);
  const key = `${j.id}|${actions}|${canAct()}|${fromRow}`;
  if (app.jobKeys.actions === key) return;
  app.jobKeys.actions = key;
  const box = $('#job-actions');
  const can = canAct();
  const kids = [];
  if (fromRow) {
    kids.push(el('label', { class: 'inline' }, 'from row ',
      el('input', { id: 'resume-from-row', type: 'number', min: 1, step: 1, inputmode: 'numeric',
        value: guessResumeRow(j), disabled: !can })));
  }
  for (const a of actions) {
    const main = a === 'start' || (a === 'retry' && !fromRow) || (a === 'resume' && fromRow);
    const cls = a === 'cancel' ? 'danger' : main ? 'primary' : '';
    kids.push(el('button', { type: 'button', class: cls, dataset: { action: a }, disabled: !can,
      text: a === 'resume' && fromRow ? 'Resume from row' : ACTION_LABELS[a] }));
  }
  if (actions.length && !can) kids.push(el('span', { class: 'note', text: actNote() }));
  box.replaceChildren(...kids);
}

// The daemon's reason for an interrupted knit says "continue with: ... --from-row N".
function guessResumeRow(j) {
  const m = /from[- ]row (\d+)/i.exec(j.reason || '');
  if (m) return m[1];
  const p = j.progress || {};
  return p.unit === 'rows' && p.done > 0 ? p.done + 1 : 1;
}

function confirmFor(action, j) {
  const where = j.device ? ` on ${j.device}` : '';
  if (action === 'start' && isLaser(j)) {
    return { title: 'Start the laser job?',
      text: `Job ${j.id} "${j.name}" starts${where}: the machine will move and the laser will fire. ` +
        'Check the material is in place, the lid is closed and the extraction runs.',
      ok: 'Start: the laser fires', no: "Don't start" };
  }
  if (action === 'cancel' && j.state === 'running') {
    const how = isLaser(j) ? 'The laser stops at once (feed hold, beam off).'
      : knits(j.kind) ? 'The machine stops after the row being knitted.' : '';
    return { title: 'Cancel the running job?', text: `Job ${j.id} "${j.name}" is running${where}. ${how}`.trim(),
      ok: 'Cancel the job', no: 'Keep it running' };
  }
  return null;
}

async function doAction(action) {
  const j = app.job && app.job.job;
  if (!j) return;
  let body;
  if (action === 'resume' && knits(j.kind) && j.state === 'interrupted') {
    const row = parseInt($('#resume-from-row').value, 10);
    if (!(row >= 1)) { setActionMessage('enter the row to resume from (1 or more)', true); return; }
    body = { from_row: row };
  }
  const c = confirmFor(action, j);
  if (c && !(await confirmDialog(c))) return;
  const buttons = [...document.querySelectorAll('#job-actions button')];
  for (const b of buttons) b.disabled = true;
  setActionMessage(`${action}…`);
  let text, error = false, answeredState = null;
  try {
    const r = await api(`/api/jobs/${encodeURIComponent(j.id)}/${action}`, { method: 'POST', body, act: true });
    text = r && r.effect ? r.effect : `${action}: done; the job is ${(r && r.state) || 'updated'}`;
    answeredState = r && r.state;
    if (r && r.settling) setTimeout(loadJob, 1500);  // the change shows shortly: look again
  } catch (e) {
    text = `${action} failed: ${e.message}`;
    error = true;
    if (e.status === 401 || e.status === 403) await loadSession();
  }
  for (const b of buttons) b.disabled = !canAct();
  await loadJob();               // rebuilds the buttons only if the allowed actions changed
  setActionMessage(text, error, error ? null : answeredState);  // last: on the settled page
}

// Kept in app.actionMsg so that it survives the page's refetches of the same job. An answer
// given in one state ("canceling ..." while running) shows only while the job is still in it:
// once the job moves on, its state and reason say what happened.
function setActionMessage(text, error, state) {
  if (text !== undefined) app.actionMsg = { id: app.route.id, text, error, state };
  const a = app.actionMsg;
  const current = !a || !a.state || (app.job && app.job.job.state === a.state);
  $('#action-message').textContent = a && current ? a.text : '';
  $('#action-message').className = `message${a && a.error ? ' error' : ''}`;
}

function renderWarnings(list) {
  $('#job-warnings').replaceChildren(...(list.length ? [el('div', { class: 'warnings', role: 'note' },
    el('h2', { text: list.length === 1 ? 'Warning' : `Warnings (${list.length})` }),
    el('ul', {}, list.map((w) => el('li', { text: w }))))] : []));
}

const fileUrl = (id, name) => `/api/jobs/${encodeURIComponent(id)}/files/${encodeURIComponent(name)}`;

function renderPreviews(j) {
  const list = j.previews || [];
  const key = `${j.id}|${j.updated}|${list.join('\n')}`;
  if (app.jobKeys.previews === key) return;   // keep loaded images on a refetch
  app.jobKeys.previews = key;
  $('#job-previews').replaceChildren(...list.map((name) => {
    const img = el('img', { class: 'preview', src: fileUrl(j.id, name), alt: `preview ${name}` });
    // Small pictures (a knit pattern, a stitch a pixel) scale up as pixels, not as a blur.
    img.addEventListener('load', () => img.classList.toggle('pixels', img.naturalWidth > 0 && img.naturalWidth < 400));
    return el('figure', {}, el('a', { href: fileUrl(j.id, name), target: '_blank', rel: 'noopener' }, img),
      el('figcaption', { text: captionOf(name) }));
  }));
}

// "fabric_preview.png" -> "fabric preview (fabric_preview.png)"
const captionOf = (name) => `${name.replace(/\.[^.]+$/, '').replace(/[_-]+/g, ' ')} (${name})`;

function renderOutputs(j) {
  const list = j.outputs || [];
  $('#job-outputs').replaceChildren(el('h2', { text: 'Outputs' }), list.length
    ? el('ul', { class: 'outputs' }, list.map((n) => el('li', {},
      el('a', { href: `${fileUrl(j.id, n)}?download=1`, download: n, text: n }))))
    : el('p', { class: 'muted', text: j.output_dir ? 'no files' : 'none yet: files appear when the job is converted' }));
}

function renderHistory(history) {
  $('#job-history').replaceChildren(el('h2', { text: 'History' }), el('div', { class: 'table-wrap' },
    el('table', { class: 'history' },
      el('thead', {}, el('tr', {}, ['When', 'From', 'To', 'Reason'].map((h) => el('th', { scope: 'col', text: h })))),
      el('tbody', {}, history.map((h) => el('tr', {},
        el('td', { 'data-label': 'When', text: fmtTime(h.at) }),
        el('td', { 'data-label': 'From' }, h.from ? badge(h.from) : '—'),
        el('td', { 'data-label': 'To' }, h.to ? badge(h.to) : '—'),
        el('td', { 'data-label': 'Reason', class: 'c-reason', text: h.reason || '' })))))));
}

// A job event for the job shown: a progress step updates in place; anything else refetches
// (history, outputs, previews and the allowed actions change with it), showing the new state
// at once meanwhile.
function jobPageEvent(ev) {
  if (!app.job) return;
  const sameState = ev.job.state === app.job.job.state;
  app.job = mergeJob(app.job, ev.job);
  $('#job-page').dataset.state = app.job.job.state;
  if (ev.progress && sameState) { renderJobLive(); return; }
  // What an action set under way ("canceling ...") has happened or been overtaken: the new
  // state and reason say it now.

  renderJob();
  scheduleJobReload();
}

// ---------------------------------------------------------------- machines

function showMachines() {
  $('#app').replaceChildren(el('section', { id: 'machines-page', class: 'page' },
    el('h1', { text: 'Machines' }), el('div', { id: 'devices', class: 'devices' })));
  renderDevices();
  loadDevices();
}

async function loadDevices() {
  const seq = app.seq;
  try {
    const d = await api('/api/devices');
    if (Array.isArray(d)) onDevices(d);
  } catch (e) {
    if (seq === app.seq && $('#devices')) $('#devices').replaceChildren(el('p', { class: 'error', text: e.message }));
  }
}

function onDevices(list) {
  app.devices = list;
  if ($('#devices')) renderDevices();
  if (app.route.page === 'job' && app.job) { renderJobDevice(); renderJobActions(); }
}

function renderDevices() {
  $('#devices').replaceChildren(...(app.devices.length ? app.devices.map(deviceCard)
    : [el('p', { class: 'muted', text: 'no devices configured' })]));
}

// What the operator is asked to do shows as a prompt.
const WAITING = /turn mark|held|hold|paus|place|swap|waiting|resume/i;

function deviceCard(d) {
  const job = d.job;
  const facts = [d.driver, d.machine, d.port].filter(Boolean).join(' · ');
  return el('div', { class: 'device card', dataset: { device: d.name, state: d.state } },
    el('div', { class: 'device-top' },
      el('h2', { text: d.name }),
      el('span', { class: `dstate d-${d.state}`, text: d.state })),
    el('p', { class: 'sub', text: facts }),
    d.detail ? el('p', { class: `detail${WAITING.test(d.detail) ? ' prompt' : ''}`, text: d.detail }) : null,
    job ? el('div', { class: 'device-job' },
      el('p', {}, 'Job ', jobLink(job.id), ' ', el('span', { class: 'job-name', text: job.name || '' })),
      progressEl(job.progress, 'running'),
      job.time_left_s != null ? el('p', { class: 'sub', text: `${fmtDuration(job.time_left_s)} left` }) : null)
      : el('p', { class: 'muted', text: 'no job' }),
    d.last ? el('p', { class: 'last' }, el('span', { class: 'sub', text: 'last: ' }), d.last) : null,
    Array.isArray(d.kinds) && d.kinds.length ? el('p', { class: 'sub', text: `takes ${d.kinds.join(', ')}` }) : null);
}

// ---------------------------------------------------------------- live

function connectEvents() {
  const es = new EventSource('/api/events');
  es.addEventListener('open', () => {
    document.body.dataset.live = '1';
    renderStatus();
    if (app.liveLost) {    // events were missed meanwhile: read everything again
      app.liveLost = false;
      loadStatus();
      loadSession();
      refreshPage();
    }
  });
  es.addEventListener('error', () => {
    document.body.dataset.live = '0';
    app.liveLost = true;
    renderStatus();
    // The browser retries by itself unless the answer was not a stream (a 503: too many open).
    if (es.readyState === EventSource.CLOSED) setTimeout(connectEvents, 5000);
  });
  es.addEventListener('job', (e) => { const ev = parseJson(e.data); if (ev && ev.job) onJobEvent(ev); });
  es.addEventListener('devices', (e) => { const d = parseJson(e.data); if (Array.isArray(d)) onDevices(d); });
}

function onJobEvent(ev) {
  const page = app.route.page;
  if (page === 'jobs' && app.list && $('#jobs-body')) listEvent(ev);
  if (page === 'job' && String(ev.job.id) === app.route.id) jobPageEvent(ev);
  if (!ev.progress) scheduleStatus();
}

// Once a second: elapsed and time left of active jobs count on between server updates.
function tick() {
  if (app.route.page === 'jobs' && app.list) {
    for (const tr of document.querySelectorAll('#jobs-body tr[data-job-id]')) {
      const rec = app.list.recs.get(tr.dataset.jobId);
      if (!rec || !ACTIVE.has(rec.job.state)) continue;
      tr.querySelector('.c-elapsed').textContent = fmtDuration(elapsedOf(rec));
      tr.querySelector('.c-left').textContent = fmtDuration(leftOf(rec));
    }
  } else if (app.route.page === 'job' && app.job) {
    const rec = app.job;
    const stateFor = $('#job-state-for');  // state_s counts on in every state
    if (stateFor) stateFor.textContent = ` for ${fmtDuration(rec.job.state_s + (Date.now() - rec.te) / 1000)}`;
    if (!ACTIVE.has(rec.job.state)) return;
    $('#job-elapsed').textContent = fmtDuration(elapsedOf(rec));
    $('#job-left').textContent = fmtDuration(leftOf(rec));
  }
}

// ---------------------------------------------------------------- confirmation dialog

// An in-page modal (not window.confirm): resolves true only on #confirm-ok.
function confirmDialog({ title, text, ok, no }) {
  const dlg = $('#confirm-dialog');
  $('#confirm-title').textContent = title;
  $('#confirm-text').textContent = text;
  $('#confirm-ok').textContent = ok || 'OK';
  $('#confirm-cancel').textContent = no || 'Back';  // never a bare "Cancel" beside "Cancel the job"
  dlg.returnValue = '';
  return new Promise((resolve) => {
    dlg.addEventListener('close', () => resolve(dlg.returnValue === 'ok'), { once: true });
    dlg.showModal();
    $('#confirm-cancel').focus();   // the safe choice is the default
  });
}

// ---------------------------------------------------------------- start

function init() {
  $('#login-panel').addEventListener('submit', submitLogin);
  $('#login-close').addEventListener('click', () => toggleLogin(false));
  // Action buttons are rebuilt often: one listener on the page for all of them.
  $('#app').addEventListener('click', (e) => {
    const b = e.target.closest('button[data-action]');
    if (b && !b.disabled) doAction(b.dataset.action);
  });
  // A file dropped beside the drop zone must not replace the page with the file.
  window.addEventListener('dragover', (e) => e.preventDefault());
  window.addEventListener('drop', (e) => e.preventDefault());
  window.addEventListener('hashchange', route);
  if (!location.hash) history.replaceState(null, '', '#/jobs');
  loadSession();
  loadStatus();
  loadDevices();
  route();
  connectEvents();
  setInterval(tick, 1000);
}

init();
