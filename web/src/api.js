// Talking to the towpath server: JSON calls with the server's error messages, and the binary
// responses of typed arrays (see crates/towpath-server/src/geometry.rs for the layout).

export class ApiError extends Error {
  constructor(status, body) {
    super(body && body.error ? body.error : `HTTP ${status}`);
    this.status = status;
    this.body = body;
  }
}

async function check(res) {
  if (res.ok) return res;
  let body = null;
  try { body = await res.json(); } catch { body = { error: await res.text().catch(() => '') || `HTTP ${res.status}` }; }
  throw new ApiError(res.status, body);
}

export async function getJson(url) {
  return (await check(await fetch(url))).json();
}

export async function sendJson(url, method, value) {
  const res = await fetch(url, { method, headers: { 'content-type': 'application/json' }, body: JSON.stringify(value) });
  return (await check(res)).json();
}

export async function sendBody(url, method, body, type = 'text/plain') {
  const res = await fetch(url, { method, headers: { 'content-type': type }, body });
  const r = await check(res);
  return r.status === 204 ? null : r.json();
}

export async function del(url) {
  await check(await fetch(url, { method: 'DELETE' }));
}

const TYPES = { f32: Float32Array, u32: Uint32Array, i32: Int32Array, u8: Uint8Array };

/** Fetches a binary blob: its header and its arrays by name, as views on the received bytes. */
export async function getBlob(url) {
  const buf = await (await check(await fetch(url))).arrayBuffer();
  const magic = new TextDecoder().decode(new Uint8Array(buf, 0, 4));
  if (magic !== 'TPB1') throw new Error(`${url}: not a towpath binary response`);
  const n = new DataView(buf).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 8, n)));
  const base = 8 + n;
  const arrays = {};
  for (const a of header.arrays) arrays[a.name] = new TYPES[a.type](buf, base + a.offset, a.length);
  return { header, arrays, bytes: buf.byteLength };
}
