// Replay controls (snapthread-web --log): play / pause, a seek bar over the log's time and
// the speed. The bridge plays the log for every page at once; these send its commands.
export class ReplayControls {
  constructor(element, send) {
    this.element = element;
    this.send = send;
    this.play = element.querySelector('#replay-play');
    this.seek = element.querySelector('#replay-seek');
    this.speed = element.querySelector('#replay-speed');
    this.time = element.querySelector('#replay-time');
    this.paused = false;
    this.seeking = false;
    this.play.addEventListener('click', () => this.send(this.paused ? 'play' : 'pause'));
    this.seek.addEventListener('input', () => { this.seeking = true; });
    this.seek.addEventListener('change', () => {
      this.seeking = false;
      this.send(`seek ${this.seek.value}`);
    });
    this.speed.addEventListener('change', () => this.send(`speed ${this.speed.value}`));
  }

  update(r) {
    this.element.hidden = false;
    this.paused = r.paused;
    this.play.textContent = r.paused ? 'play' : 'pause';
    this.seek.max = r.duration_s;
    if (!this.seeking) this.seek.value = r.t_s;
    if (Number(this.speed.value) !== r.speed && document.activeElement !== this.speed) this.speed.value = String(r.speed);
    this.time.textContent = `${r.t_s.toFixed(1)} / ${r.duration_s.toFixed(1)} s · shape ${r.shape_index} / ${r.shape_count}${r.at_end ? ' · end' : ''}`;
    const d = document.body.dataset;
    d.replayShape = r.shape_index;
    d.replayShapes = r.shape_count;
    d.replayAtEnd = r.at_end;
  }
}
