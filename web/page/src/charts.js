// Live uPlot charts of the force models: |F| (N), the update's solve time (us) and the
// residual ||E_x|| (log scale), over the last WINDOW_S seconds. Points are kept as they
// come (at most 60 Hz from the bridge) and the charts redrawn at 5 Hz.
import uPlot from 'uplot';

const WINDOW_S = 20;

// Axis labels: plain numbers where they read well, powers of ten for the residual.
function tick(v, log) {
  if (v === null || v === undefined) return '';
  if (log || (v !== 0 && (Math.abs(v) < 1e-2 || Math.abs(v) >= 1e5))) return v.toExponential(0);
  return String(Number(v.toPrecision(3)));
}

function chart(parent, title, label, colour, log) {
  const opts = {
    title, width: 340, height: 110,
    scales: { x: { time: false }, y: log ? { distr: 3 } : {} },
    axes: [{ stroke: '#aaa', grid: { stroke: '#333' } },
           { stroke: '#aaa', grid: { stroke: '#333' }, size: 60,
             values: (u, splits) => splits.map((v) => tick(v, log)) }],
    series: [{ label: 't (s)' }, { label, stroke: colour, width: 1.5, points: { show: false } }],
    legend: { show: false },
  };
  return new uPlot(opts, [[], []], parent);
}

export class Charts {
  constructor(parent) {
    this.t = []; this.force = []; this.solve = []; this.residual = [];
    this.start = performance.now();
    this.plots = [
      chart(parent, '|F| (N)', '|F|', '#ff5940', false),
      chart(parent, 'update time (us)', 'solve', '#8cccf2', false),
      chart(parent, 'residual ||E_x||', 'residual', '#f0c040', true),
    ];
    setInterval(() => this.redraw(), 200);
  }

  addForceModel(m) {
    const t = (performance.now() - this.start) / 1000;
    this.t.push(t);
    this.force.push(m.f_n);
    this.solve.push(m.solve_us);
    // The log scale needs positive values; an exact 0 sits at the floor.
    this.residual.push(Math.max(m.residual ?? 0, 1e-16));
    while (this.t.length && this.t[0] < t - WINDOW_S) {
      this.t.shift(); this.force.shift(); this.solve.shift(); this.residual.shift();
    }
    this.dirty = true;
  }

  redraw() {
    if (!this.dirty) return;
    this.dirty = false;
    this.plots[0].setData([this.t, this.force]);
    this.plots[1].setData([this.t, this.solve]);
    this.plots[2].setData([this.t, this.residual]);
  }
}
