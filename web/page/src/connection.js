// The WebSocket to the bridge: /ws on the page's own host, reconnecting after a drop.
// Beyond loopback the bridge needs the observer token: the browser sends it in the
// HttpOnly cookie the bridge set when the page was first opened with ?token= (the page
// never sees it), like every other request of the page.
// Sends "ping <ms>" once a second; the bridge's "pong" gives the browser round trip.
export class Connection {
  constructor(onMessage, onState) {
    this.onMessage = onMessage;
    this.onState = onState;
    this.roundTripMs = NaN;
    this.open();
    setInterval(() => this.send(`ping ${performance.now()}`), 1000);
  }

  url() {
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    return `${scheme}//${location.host}/ws`;
  }

  open() {
    this.ws = new WebSocket(this.url());
    this.onState('connecting');
    this.ws.onopen = () => this.onState('open');
    this.ws.onclose = () => {
      this.onState('closed');
      setTimeout(() => this.open(), 1000);
    };
    this.ws.onmessage = (event) => {
      let message;
      try {
        message = JSON.parse(event.data);
      } catch {
        return;
      }
      if (message.type === 'pong') {
        this.roundTripMs = performance.now() - message.t;
        return;
      }
      this.onMessage(message);
    };
  }

  send(text) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(text);
  }
}
