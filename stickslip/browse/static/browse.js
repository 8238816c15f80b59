// The tables of a study's pages: sort by a heading's click, filter by the inputs under the headings.
// Runs in the page only: it sends nothing and loads nothing.
"use strict";

function cellValue(row, index) {
  return row.cells[index].textContent.trim();
}

function asNumber(text) {
  return text === "" ? NaN : Number(text);
}

// A filter's test of one cell: ">0.1", "<=3", "=2", "!=1" compare numbers; any other text matches anywhere.
function matcher(text) {
  const match = /^(<=|>=|!=|<|>|=)\s*(.+)$/.exec(text);
  if (match && !isNaN(asNumber(match[2]))) {
    const bound = asNumber(match[2]);
    const compare = {"<": (v) => v < bound, ">": (v) => v > bound, "<=": (v) => v <= bound,
                     ">=": (v) => v >= bound, "=": (v) => v === bound, "!=": (v) => v !== bound}[match[1]];
    return (cell) => { const value = asNumber(cell); return !isNaN(value) && compare(value); };
  }
  const needle = text.toLowerCase();
  return (cell) => cell.toLowerCase().includes(needle);
}

function applyFilters(table) {
  const tests = Array.from(table.querySelectorAll("tr.filters input")).map(
    (input, index) => [index, input.value.trim()]).filter(([, text]) => text !== "").map(
    ([index, text]) => [index, matcher(text)]);
  let shown = 0;
  const rows = table.tBodies[0].rows;
  for (const row of rows) {
    const visible = tests.every(([index, test]) => test(cellValue(row, index)));
    row.hidden = !visible;
    shown += visible ? 1 : 0;
  }
  const counter = document.getElementById(table.id.replace("-table", "-count"));
  if (counter) counter.textContent = `${shown} of ${rows.length} shown.`;
}

function sortBy(table, index, heading) {
  const up = !heading.classList.contains("sorted-up");
  table.querySelectorAll("thead th").forEach((th) => th.classList.remove("sorted-up", "sorted-down"));
  heading.classList.add(up ? "sorted-up" : "sorted-down");
  const body = table.tBodies[0];
  const rows = Array.from(body.rows);
  rows.sort((a, b) => {
    const x = cellValue(a, index), y = cellValue(b, index);
    const nx = asNumber(x), ny = asNumber(y);
    const order = !isNaN(nx) && !isNaN(ny) ? nx - ny : x.localeCompare(y);
    return up ? order : -order;
  });
  rows.forEach((row) => body.appendChild(row));
}

document.querySelectorAll("table.data").forEach((table) => {
  const headings = table.tHead.rows[0].cells;
  Array.from(headings).forEach((heading, index) => {
    heading.addEventListener("click", () => sortBy(table, index, heading));
  });
  table.querySelectorAll("tr.filters input").forEach((input) => {
    input.addEventListener("input", () => applyFilters(table));
  });
  if (table.classList.contains("filtered")) applyFilters(table);
});
