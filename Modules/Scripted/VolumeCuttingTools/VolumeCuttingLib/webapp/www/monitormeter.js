// The nerve monitor's meter in the Drill panel: <vc-monitor-meter> shows the rows the server publishes in the trame
// state (vc_monitor: [{name, mm, bar, level, colour}]). Watched here and drawn into the element directly, not from the
// page's template, which would render the whole page again at each update while the tool moves.
(function () {
  let rows = [];

  function row(reading) {
    const line = document.createElement("div");
    line.className = "vc-monitor-row";
    line.dataset.monitorOf = reading.name;
    line.dataset.level = reading.level;
    line.dataset.mm = reading.mm === null ? "" : String(reading.mm);
    line.style.cssText = "display:flex;align-items:center;gap:6px;font-size:12px;line-height:18px;";
    const name = document.createElement("span");
    name.textContent = reading.name;
    name.style.cssText = "flex:0 0 36%;overflow:hidden;text-overflow:ellipsis;white-space:nowrap;";
    name.title = reading.name;
    const bar = document.createElement("span");
    bar.style.cssText = "flex:1 1 auto;min-width:30px;height:10px;border:1px solid #9e9e9e;border-radius:2px;background:#fafafa;" +
      "position:relative;overflow:hidden;";
    const fill = document.createElement("span");
    fill.className = "vc-monitor-fill";
    fill.style.cssText = `position:absolute;left:0;top:0;bottom:0;width:${Math.round(reading.bar * 1000) / 10}%;` +
      `background:${reading.colour};`;
    bar.appendChild(fill);
    const figure = document.createElement("span");
    figure.className = "vc-monitor-figure";
    figure.style.cssText = "flex:0 0 auto;min-width:10.5em;padding:0 4px;border-radius:2px;white-space:nowrap;" +
      `font-size:11px;background:${reading.colour};`;
    figure.textContent = reading.mm === null ? "not ready" : `${reading.mm.toFixed(2)} mm ${reading.level}`;
    line.append(name, bar, figure);
    return line;
  }

  function render(element) {
    if (!rows.length) {
      element.replaceChildren();
      return;
    }
    const title = document.createElement("div");
    title.textContent = "Nerve monitor (distance from the burr, 0-8 mm)";
    title.style.cssText = "font-size:13px;margin-top:6px;";
    element.replaceChildren(title, ...rows.map(row));
  }

  // An element of its own: when the Drill panel opens again Vue makes a new one, which draws the latest rows.
  class MonitorMeter extends HTMLElement {
    connectedCallback() {
      this.style.display = "block";
      render(this);
    }
  }
  if (!customElements.get("vc-monitor-meter")) customElements.define("vc-monitor-meter", MonitorMeter);

  const meter = {
    updates: 0,
    update(value) {
      rows = Array.isArray(value) ? value : [];
      meter.updates += 1;
      document.querySelectorAll("vc-monitor-meter").forEach(render);
    },
  };
  window.vcMonitorMeter = meter;
  (function register(attempts) {
    const trame = window.trame;
    if (!trame || !trame.state || !trame.state.watch) {
      if (attempts > 0) setTimeout(() => register(attempts - 1), 10);  // a page without trame: stop after 30 s
      return;
    }
    meter.update(trame.state.get("vc_monitor"));
    trame.state.watch(["vc_monitor"], (value) => meter.update(value));
  })(3000);
})();
