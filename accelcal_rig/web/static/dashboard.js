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
    line: p.line || c.last_event || "",
    finished: c.finished || "—",
  };
}

function fill(element, fields) {
  for (const cell of element.querySelectorAll("[data-field]")) {
    const value = fields[cell.dataset.field];
    if (value !== undefined && cell.textContent !== value) { cell.textContent = value; }
  }
}

async function refresh(target) {
  try {
    const response = await fetch(target.dataset.refresh, { credentials: "same-origin" });
    if (!response.ok) { return; }
    const data = await response.json();
    if (Array.isArray(data)) {
      const rows = new Map([...target.querySelectorAll("tr[data-name]")].map((row) => [row.dataset.name, row]));
      if (data.some((c) => !rows.has(c.name))) { window.location.reload(); return; }
      for (const c of data) { fill(rows.get(c.name), progressFields(c)); rows.get(c.name).className = `state-${c.state}`; }
    } else {
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
