// The dashboard's pages refresh themselves: every two seconds the element with data-refresh fetches its JSON
// and writes the fields it shows (no framework, no network beyond this server).
"use strict";

function degrees(value, digits) { return value === null || value === undefined ? "—" : value.toFixed(digits) + " °C"; }

function progressFields(c) {
  const p = c.progress || {};
  return {
    state: c.state,
    phase: p.phase || "—",
    setpoint: p.setpoint_c === null || p.setpoint_c === undefined ? "—"
      : `${p.setpoint_c} °C (${p.setpoint_number}/${p.setpoints_total})`,
    chamber: degrees(p.chamber_c, 1),
    duts: p.dut_c && p.dut_c.length ? `${Math.min(...p.dut_c).toFixed(2)}…${Math.max(...p.dut_c).toFixed(2)} °C` : "—",
    poses: `${c.poses_done}/${c.poses_total}`,
    left: p.left || "—",
    warnings: String((c.warnings || []).length),
    line: p.now || c.last_event || "",  // the progress line without its pose count: the poses field is the journal's
    finished: c.finished || "—",
    sensor_verdicts: c.sensor_verdicts || "",  // an IMU campaign's verdicts per sensor
  };
}

function fill(element, fields) {
  for (const cell of element.querySelectorAll("[data-field]")) {
    const value = fields[cell.dataset.field];
    if (value !== undefined && cell.textContent !== value) { cell.textContent = value; }
  }
}

// A campaign's verdicts in one cell, as verdict.html's verdict_counts writes them: a count per verdict, worst first.
const VERDICTS = ["FAIL", "CONDITIONAL", "PASS", "NOT JUDGED"];

function fillVerdicts(cell, verdicts) {
  const spans = [];
  for (const value of VERDICTS) {
    const serials = Object.keys(verdicts || {}).sort().filter((serial) => verdicts[serial].verdict === value);
    if (!serials.length) { continue; }
    const span = document.createElement("span");
    span.className = `verdict verdict-${value.toLowerCase().replace(" ", "-")}`;
    span.title = serials.join(", ");
    span.textContent = `${serials.length} ${value}`;
    spans.push(span, document.createTextNode(" "));
  }
  const text = spans.map((node) => node.textContent).join("") || "—";
  if (cell.textContent.trim() !== text.trim()) { cell.replaceChildren(...(spans.length ? spans : [document.createTextNode("—")])); }
}

async function refresh(target) {
  try {
    const response = await fetch(target.dataset.refresh, { credentials: "same-origin" });
    if (!response.ok) { return; }
    const data = await response.json();
    if (Array.isArray(data)) {
      const rows = new Map([...target.querySelectorAll("tr[data-name]")].map((row) => [row.dataset.name, row]));
      if (data.some((c) => !rows.has(c.name))) { window.location.reload(); return; }
      for (const c of data) {
        const row = rows.get(c.name);
        fill(row, progressFields(c));
        row.className = `state-${c.state}`;
        const cell = row.querySelector("[data-verdicts]");
        if (cell) { fillVerdicts(cell, c.verdicts); }
      }
    } else {
      // verdicts judged or a resume recorded since the page was made: its tables and plot are the server's
      const verdicts = Object.keys(data.verdicts || {}).length, stops = (data.interruptions || []).length;
      if (String(verdicts) !== target.dataset.verdicts || String(stops) !== target.dataset.interruptions) {
        window.location.reload();
        return;
      }
      fill(target, progressFields(data));
    }
  } catch (error) {
    // the server is gone for a moment (restarted, asleep): the next tick tries again
  }
}

document.addEventListener("DOMContentLoaded", () => {
  for (const target of document.querySelectorAll("[data-refresh]")) {
    window.setInterval(() => refresh(target), 2000);
  }
});

// What the lab's rigs publish to the registry is pushed: the server's event stream says when something changed
// (and ticks every few seconds, so a rig gone quiet turns stale on the page without a reload); the element
// with data-live then fetches its address again and takes the part of the answer with its own id.
async function reload(target) {
  try {
    const response = await fetch(target.dataset.live, { credentials: "same-origin" });
    if (!response.ok) { return; }
    const page = new DOMParser().parseFromString(await response.text(), "text/html");
    const part = page.getElementById(target.id);
    const html = part ? part.innerHTML : page.body.innerHTML;
    if (target.innerHTML !== html) { target.innerHTML = html; }
    target.dataset.reloads = String(Number(target.dataset.reloads || 0) + 1);
  } catch (error) {
    // the server is gone for a moment: the stream's next event tries again
  }
}

document.addEventListener("DOMContentLoaded", () => {
  const targets = [...document.querySelectorAll("[data-live]")];
  if (!targets.length) { return; }
  const again = () => { for (const target of targets) { reload(target); } };
  if (window.EventSource) {
    const stream = new EventSource("/api/live/stream");
    stream.addEventListener("change", again);
    stream.addEventListener("tick", again);
  } else {
    window.setInterval(again, 5000);  // polling only where there is no event stream
  }
});
