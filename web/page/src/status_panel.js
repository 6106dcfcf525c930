// The status panel: what the page measures (shapes and frames per second, the shape's
// age, the browser round trip), the server's solver status, the device's status (tick
// rate, lateness, pose -> model round trip), the last force model's certified force error
// and the bridge's counters.
// Every text here comes from the session's messages or a log, so it is hostile: it goes
// into the page only as DOM text (textContent), never as markup.
import { STATUS_NAMES, statusColour, css } from './colours.js';

const fmt = (v, digits = 0) => (v === undefined || v === null || Number.isNaN(v) ? '–' : Number(v).toFixed(digits));
const exp = (v) => (v === undefined || v === null ? '–' : Number(v).toExponential(2));
// force_model_t.force_error_n: newtons, or -1 when the server could make no estimate.
export const FORCE_ERROR_KEY = 'force error (certified)';
export const forceErrorText = (v) => {
  if (v === undefined || v === null || Number.isNaN(Number(v))) return '–';
  return Number(v) < 0 ? 'none' : `${Number(v).toExponential(2)} N`;
};

export class StatusPanel {
  constructor(element) {
    this.element = element;
    this.solver = null; this.device = null; this.bridge = null; this.shape = null; this.force = null;
  }

  render(page) {
    const s = this.solver, d = this.device, b = this.bridge, sh = this.shape;
    const rows = [
      ['page', ''],
      ['shapes / s', fmt(page.shapeRate)], ['frames / s', fmt(page.frameRate)],
      ['shape age', `${fmt(page.shapeAgeMs, 1)} ms`], ['browser round trip', `${fmt(page.roundTripMs, 1)} ms`],
      ['shapes / frames', `${page.shapes} / ${page.frames}`],
      ['server', s ? `${s.scene} · ${s.method}` : 'waiting'],
    ];
    if (sh) {
      const state = document.createElement('span');
      state.style.color = css(statusColour(sh.status));
      state.textContent = STATUS_NAMES[sh.status] ?? String(sh.status);
      rows.push(['state', state]);
      rows.push(['model · nodes', `${sh.model} · ${sh.positions.length / 3}`], ['snaps', sh.snaps]);
      if (sh.knot) rows.push(['knot', sh.knot]);
      if (sh.contacts) rows.push(['contacts', sh.contacts.length / 6]);
    }
    if (this.force) rows.push([FORCE_ERROR_KEY, forceErrorText(this.force.force_error_n)]);
    if (s) {
      rows.push(['updates / s', fmt(s.update_rate_hz)], ['solve p50 / p99', `${fmt(s.solve_us_p50)} / ${fmt(s.solve_us_p99)} us`],
                ['iterations', s.iterations], ['residual', exp(s.residual)], ['lambda_min', exp(s.lambda_min)],
                ['dropped poses', s.dropped_poses]);
    }
    rows.push(['device', d ? d.device_id : 'waiting']);
    if (d) {
      rows.push(['ticks / s', fmt(d.tick_rate_hz)],
                ['lateness p50 / p99 / max', `${fmt(d.lateness_us_p50)} / ${fmt(d.lateness_us_p99)} / ${fmt(d.lateness_us_max)} us`],
                ['round trip p50 / p99', `${fmt(d.round_trip_us_p50)} / ${fmt(d.round_trip_us_p99)} us`],
                ['model age', `${fmt(d.model_age_ms, 1)} ms`], ['|F| commanded', `${fmt(d.force_norm_n, 3)} N`],
                ['clamps · fades', `${d.force_clamps} · ${d.fades}`]);
    }
    if (b) {
      rows.push(['bridge', `${b.mode} · ${b.session}`], ['pages', b.clients],
                ['refused (malformed · auth)', `${b.malformed} · ${b.auth_rejected}`],
                ['shapes dropped (slow pages)', b.shapes_dropped],
                ['requests refused (401 · 403 · pages)',
                 `${b.unauthorized ?? 0} · ${b.forbidden ?? 0} · ${(b.pages_refused ?? 0) + (b.connections_refused ?? 0)}`]);
    }
    this.element.replaceChildren(...rows.map(([k, v]) => row(k, v)));
  }
}

// One row: a heading row for the sections (page, server, device, bridge), else a key and
// its value (text, or a node built above).
function row(key, value) {
  const tr = document.createElement('tr');
  if (value === '' || key === 'server' || key === 'device' || key === 'bridge') {
    tr.className = 'head';
    const th = document.createElement('th');
    th.colSpan = 2;
    th.textContent = `${key} ${value}`;
    tr.append(th);
    return tr;
  }
  const k = document.createElement('td');
  k.textContent = key;
  const v = document.createElement('td');
  if (value instanceof Node) v.append(value);
  else v.textContent = String(value);
  tr.append(k, v);
  return tr;
}
