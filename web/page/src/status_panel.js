// The status panel: what the page measures (shapes and frames per second, the shape's
// age, the browser round trip), the server's solver status, the device's status (tick
// rate, lateness, pose -> model round trip) and the bridge's counters.
import { STATUS_NAMES, statusColour, css } from './colours.js';

const fmt = (v, digits = 0) => (v === undefined || v === null || Number.isNaN(v) ? '–' : Number(v).toFixed(digits));
const exp = (v) => (v === undefined || v === null ? '–' : Number(v).toExponential(2));

export class StatusPanel {
  constructor(element) {
    this.element = element;
    this.solver = null; this.device = null; this.bridge = null; this.shape = null;
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
      rows.push(['state', `<span style="color:${css(statusColour(sh.status))}">${STATUS_NAMES[sh.status] ?? sh.status}</span>`]);
      rows.push(['model · nodes', `${sh.model} · ${sh.positions.length / 3}`], ['snaps', sh.snaps]);
      if (sh.knot) rows.push(['knot', sh.knot]);
      if (sh.contacts) rows.push(['contacts', sh.contacts.length / 6]);
    }
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
                ['shapes dropped (slow pages)', b.shapes_dropped]);
    }
    this.element.innerHTML = rows
      .map(([k, v]) => (v === '' || k === 'server' || k === 'device' || k === 'bridge'
        ? `<tr class="head"><th colspan="2">${k} ${v}</th></tr>` : `<tr><td>${k}</td><td>${v}</td></tr>`))
      .join('');
  }
}
