// The machine module: axes and DH joints edited in place, checked by the server as you type,
// with the tool point for given axis values and the TOML that will be saved.

import { getJson, sendJson, sendBody, del } from './api.js';

const $ = (id) => document.getElementById(id);
const KINDS = ['linear', 'rotary', 'continuous', 'mandrel'];
let machine = null;
let values = [];
let timer = null;

function num(v) { const x = parseFloat(v); return Number.isFinite(x) ? x : undefined; }

function message(el, text) { el.hidden = !text; el.textContent = text || ''; }

function axisRow(a, i) {
  const tr = document.createElement('tr');
  const cell = (html) => { const td = document.createElement('td'); td.innerHTML = html; tr.appendChild(td); return td; };
  cell(`<input value="${a.label}" data-k="label" size="3">`);
  cell(`<select data-k="kind">${KINDS.map((k) => `<option ${k === a.kind ? 'selected' : ''}>${k}</option>`).join('')}</select>`);
  for (const k of ['weight', 'min', 'max', 'home', 'max_velocity', 'max_acceleration']) cell(`<input type="number" step="any" data-k="${k}" value="${a[k] ?? ''}">`);
  cell(`<input type="checkbox" data-k="heading" ${a.heading ? 'checked' : ''} title="heading axis (turned 180° on a reversed course)">`);
  cell(a.kind === 'mandrel' ? `<input data-k="direction" value="${(a.direction || [1, 0, 0]).join(',')}" size="6" title="mandrel axis direction">` : '');
  cell(`<button data-del="${i}" title="remove this axis">×</button>`);
  tr.addEventListener('input', (e) => edit(a, e.target));
  tr.addEventListener('change', (e) => edit(a, e.target));
  tr.querySelector('[data-del]').onclick = () => { machine.axis.splice(i, 1); values.splice(i, 1); render(); };
  return tr;
}

function edit(obj, input) {
  const k = input.dataset.k;
  if (!k) return;
  if (input.type === 'checkbox') obj[k] = input.checked;
  else if (k === 'label' || k === 'kind' || k === 'axis') obj[k] = input.value || undefined;
  else if (k === 'direction') obj[k] = input.value.split(',').map(Number);
  else { const v = num(input.value); if (v === undefined) delete obj[k]; else obj[k] = v; }
  if (k === 'kind') render(); else schedule();
}

function render() {
  const t = $('m-axes');
  t.innerHTML = '<tr><th>label</th><th>kind</th><th>weight</th><th>min</th><th>max</th><th>home</th><th>max vel.</th><th>max acc.</th><th>heading</th><th>mandrel dir.</th><th></th></tr>';
  machine.axis.forEach((a, i) => t.appendChild(axisRow(a, i)));
  const d = $('m-dh');
  d.innerHTML = '<tr><th>a (mm)</th><th>d (mm)</th><th>α (°)</th><th>θ (°)</th><th>driven by axis</th><th></th></tr>';
  (machine.dh || []).forEach((j, i) => {
    const tr = document.createElement('tr');
    tr.innerHTML = ['a', 'd', 'alpha', 'theta'].map((k) => `<td><input type="number" step="any" data-k="${k}" value="${j[k] ?? 0}"></td>`).join('') +
      `<td><select data-k="axis"><option value="">fixed</option>${machine.axis.map((a) => `<option ${a.label === j.axis ? 'selected' : ''}>${a.label}</option>`).join('')}</select></td><td><button>×</button></td>`;
    tr.addEventListener('input', (e) => edit(j, e.target));
    tr.addEventListener('change', (e) => edit(j, e.target));
    tr.querySelector('button').onclick = () => { machine.dh.splice(i, 1); render(); };
    d.appendChild(tr);
  });
  $('m-head-on').checked = !!machine.head;
  $('m-head').hidden = !machine.head;
  for (const k of ['radius', 'bottom', 'top']) $(`m-head-${k}`).value = machine.head ? machine.head[k] ?? '' : '';
  const vs = $('m-values');
  vs.innerHTML = '';
  machine.axis.forEach((a, i) => {
    if (values[i] === undefined) values[i] = a.home || 0;
    const l = document.createElement('label');
    l.innerHTML = `${a.label || '?'} <input type="number" step="any" value="${values[i]}">`;
    l.querySelector('input').addEventListener('input', (e) => { values[i] = num(e.target.value) ?? 0; schedule(); });
    vs.appendChild(l);
  });
  schedule();
}

function schedule() { clearTimeout(timer); timer = setTimeout(preview, 120); }

async function preview() {
  message($('m-ok'), '');
  try {
    const r = await sendJson('/api/machine-preview', 'POST', { machine, values: values.slice(0, machine.axis.length) });
    message($('m-error'), '');
    $('m-toml').textContent = r.toml;
    const tp = r.tool_point;
    const f = (p) => p.map((x) => x.toFixed(3)).join(', ');
    $('m-tp').innerHTML = tp ? `<div>machine frame <b>${f(tp.machine)}</b></div><div>part frame <b>${f(tp.part)}</b></div>` : '<div class="muted">no kinematics: add X/Y/Z axes or a DH chain</div>';
  } catch (e) {
    message($('m-error'), e.message);
  }
}

async function load(name) {
  const r = await getJson(`/api/machines/${encodeURIComponent(name)}`);
  machine = r.machine;
  machine.dh = machine.dh || [];
  values = machine.axis.map((a) => a.home || 0);
  $('m-name').value = r.builtin ? `${name}-copy` : name;
  $('m-delete').disabled = r.builtin;
  render();
}

async function refresh(select) {
  const { machines } = await getJson('/api/machines');
  $('m-select').innerHTML = machines.map((m) => `<option value="${m.name}">${m.name}${m.builtin ? ' (built in)' : ''}</option>`).join('');
  if (select) $('m-select').value = select;
  const up = $('upload-machine');
  if (up) up.innerHTML = machines.map((m) => `<option>${m.name}</option>`).join('');
}

export async function initMachine() {
  await refresh();
  await load($('m-select').value);
  $('m-select').onchange = (e) => load(e.target.value);
  $('m-add-axis').onclick = () => { machine.axis.push({ label: 'U', kind: 'linear', weight: 1 }); render(); };
  $('m-add-dh').onclick = () => { machine.dh.push({ a: 0, d: 0, alpha: 0, theta: 0 }); render(); };
  // The head: a capsule along the tool axis (towpath_machine::Head); a typical AFP head to start.
  $('m-head-on').onchange = (e) => {
    if (e.target.checked) machine.head = { radius: 40, bottom: 45, top: 300 };
    else delete machine.head;
    render();
  };
  $('m-head').addEventListener('input', (e) => {
    const k = e.target.dataset.k;
    if (!k || !machine.head) return;
    const v = num(e.target.value);
    if (v === undefined) delete machine.head[k]; else machine.head[k] = v;
    schedule();
  });
  $('m-save').onclick = async () => {
    const name = $('m-name').value.trim();
    try {
      machine.name = name;
      await sendJson(`/api/machines/${encodeURIComponent(name)}`, 'PUT', machine);
      await refresh(name);
      await load(name);
      message($('m-ok'), `saved as ${name}.toml in the workspace`);
    } catch (e) { message($('m-error'), e.message); }
  };
  $('m-delete').onclick = async () => {
    const name = $('m-select').value;
    try { await del(`/api/machines/${encodeURIComponent(name)}`); await refresh(); await load($('m-select').value); } catch (e) { message($('m-error'), e.message); }
  };
  $('m-download').onclick = () => {
    const a = document.createElement('a');
    a.href = URL.createObjectURL(new Blob([$('m-toml').textContent], { type: 'text/plain' }));
    a.download = `${$('m-name').value || 'machine'}.toml`;
    a.click();
  };
  $('m-file').onchange = async (e) => {
    const f = e.target.files[0];
    if (!f) return;
    const name = f.name.replace(/\.toml$/i, '').replace(/[^A-Za-z0-9._-]/g, '_');
    try {
      await sendBody(`/api/machines/${encodeURIComponent(name)}`, 'PUT', await f.text());
      await refresh(name);
      await load(name);
      message($('m-ok'), `${f.name} loaded and saved as ${name}`);
    } catch (err) { message($('m-error'), err.message); }
    e.target.value = '';
  };
  $('d-file').onchange = async (e) => {
    const f = e.target.files[0];
    if (!f) return;
    const name = f.name.replace(/\.toml$/i, '').replace(/[^A-Za-z0-9._-]/g, '_');
    try {
      await sendBody(`/api/dialects/${encodeURIComponent(name)}`, 'PUT', await f.text());
      message($('m-ok'), `dialect ${name} saved; choose it when opening a program`);
      const { dialects } = await getJson('/api/dialects');
      $('upload-dialect').innerHTML = dialects.map((d) => `<option>${d.name}</option>`).join('');
    } catch (err) { message($('m-error'), err.message); }
    e.target.value = '';
  };
}
