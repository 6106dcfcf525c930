// snapthread-web's page: connects to the bridge, draws every shape it gets, charts the
// force models and shows the statuses. Test hooks (cumulative counters, read by the
// browser tests): document.body.dataset.shapesReceived and .framesDrawn; also .lastShapeSeq,
// .lastShapeStatus, .lastShapeUtime (the server's stamp), .connection, .roundTripMs (the
// last ping's, refreshed 4 times a second), and in replay .replayShape / .replayShapes / .replayAtEnd.
import { SceneView } from './scene_view.js';
import { Charts } from './charts.js';
import { StatusPanel } from './status_panel.js';
import { ReplayControls } from './replay_controls.js';
import { Connection } from './connection.js';

const data = document.body.dataset;
const view = new SceneView(document.getElementById('view'));
const charts = new Charts(document.getElementById('charts'));
const panel = new StatusPanel(document.getElementById('status'));
let shapes = 0, frames = 0;
let shapeTimes = [], frameTimes = [];
let lastShape = null;
data.shapesReceived = 0;
data.framesDrawn = 0;

const connection = new Connection(onMessage, (state) => { data.connection = state; });
const replay = new ReplayControls(document.getElementById('replay'), (c) => connection.send(c));

function onMessage(m) {
  // The bridge keeps at most a few shapes and force models unacknowledged per page, so a
  // page that falls behind gets the latest ones, not a backlog (web/client_pacer.h).
  if (m.type === 'shape' || m.type === 'force') connection.send('ack');
  switch (m.type) {
    case 'shape':
      view.setShape(m);
      lastShape = m;
      panel.shape = m;
      shapes += 1;
      shapeTimes.push(performance.now());
      data.shapesReceived = shapes;
      data.lastShapeSeq = m.seq;
      data.lastShapeStatus = m.status;
      data.lastShapeUtime = m.utime;
      break;
    case 'force': charts.addForceModel(m); panel.force = m; break;
    case 'solver': panel.solver = m; break;
    case 'device': panel.device = m; break;
    case 'bridge': panel.bridge = m; data.mode = m.mode; break;
    case 'replay': replay.update(m); break;
    default: break;
  }
}

// Events in the last second.
function rate(times, now) {
  while (times.length && times[0] < now - 1000) times.shift();
  return times.length;
}

function frame() {
  requestAnimationFrame(frame);
  if (view.draw()) {
    frames += 1;
    frameTimes.push(performance.now());
    data.framesDrawn = frames;
  }
}
requestAnimationFrame(frame);

setInterval(() => {
  const now = performance.now();
  data.roundTripMs = connection.roundTripMs.toFixed(1);
  panel.render({
    shapes, frames,
    shapeRate: rate(shapeTimes, now), frameRate: rate(frameTimes, now),
    // The server stamps shapes with its wall clock: meaningful when the browser runs on a
    // machine with the same clock (NTP), as in a lab.
    shapeAgeMs: lastShape ? Date.now() - lastShape.utime / 1000 : NaN,
    roundTripMs: connection.roundTripMs,
  });
}, 250);
