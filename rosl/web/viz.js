// rosl viz --serve: draws the snapshots rosl sends over server-sent events (/events).
//
// The world is drawn as rosl/sim/render.py draws its SVG/PNG (same colours, 900 px wide, the
// same metres-to-pixels view and label placement); the graph as `rosl graph` draws it (nodes as
// ellipses, topics as boxes, publisher -> topic -> subscriber), in columns by longest path.
// Stable ids/classes for tests: #scan .scan-point, .path, .footprint, .frame, #robot (its
// data-x/-y/-yaw: the first robot's pose in the fixed frame), .graph-node, .graph-topic.
"use strict";

(function () {
  const SVG = "http://www.w3.org/2000/svg";
  const WIDTH = 900;
  const TOP = 28; // room for the title
  const BOTTOM = 10;
  const PATH_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"];
  const LABEL_OFFSET = 4;
  const LABEL_GAP = 2;
  const AXIS_PX = 30;

  const $ = (id) => document.getElementById(id);
  const f1 = (v) => v.toFixed(1);

  function el(name, attrs, parent) {
    const node = document.createElementNS(SVG, name);
    for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, String(value));
    if (parent) parent.appendChild(node);
    return node;
  }

  function clear(node) {
    while (node.firstChild) node.removeChild(node.firstChild);
  }

  // --- the world ---------------------------------------------------------------------------

  let bounds = null; // grows only (per fixed frame), so the picture does not jump
  let boundsFrame = null;
  let updates = 0;

  function grow(next, frame) {
    if (bounds === null || frame !== boundsFrame) {
      bounds = next.slice();
      boundsFrame = frame;
    } else {
      bounds = [
        Math.min(bounds[0], next[0]), Math.min(bounds[1], next[1]),
        Math.max(bounds[2], next[2]), Math.max(bounds[3], next[3]),
      ];
    }
    return bounds;
  }

  function makeView(b) {
    const [x0, y0, x1, y1] = b;
    const scale = WIDTH / (x1 - x0);
    const height = Math.max(1, Math.round((y1 - y0) * scale));
    const at = (p) => [(p[0] - x0) * scale, TOP + (y1 - p[1]) * scale];
    return { scale, height, at };
  }

  function overlaps(a, b, gap) {
    return a[0] < b[2] + gap && b[0] < a[2] + gap && a[1] < b[3] + gap && b[1] < a[3] + gap;
  }

  // rosl.sim.render.place_labels: below-right, above-right, below-left, above-left, else down
  function placeLabels(anchors, sizes) {
    const placed = [];
    anchors.forEach(([x, y], i) => {
      const [w, h] = sizes[i];
      const corners = [
        [x + LABEL_OFFSET, y + LABEL_OFFSET], [x + LABEL_OFFSET, y - LABEL_OFFSET - h],
        [x - LABEL_OFFSET - w, y + LABEL_OFFSET], [x - LABEL_OFFSET - w, y - LABEL_OFFSET - h],
      ];
      const boxes = corners.map(([l, t]) => [l, t, l + w, t + h]);
      let box = boxes.find((b) => !placed.some((p) => overlaps(b, p, LABEL_GAP)));
      if (box === undefined) {
        box = boxes[0];
        let hit;
        while ((hit = placed.find((p) => overlaps(box, p, LABEL_GAP))) !== undefined) {
          const top = hit[3] + LABEL_GAP + 1e-6;
          box = [box[0], top, box[2], top + h];
        }
      }
      placed.push(box);
    });
    return placed;
  }

  function moved(box, [x, y], reach) {
    const dx = Math.max(box[0] - x, x - box[2], 0);
    const dy = Math.max(box[1] - y, y - box[3], 0);
    return dx > reach || dy > reach;
  }

  function nearestCorner(box, [x, y]) {
    const corners = [[box[0], box[1]], [box[2], box[1]], [box[0], box[3]], [box[2], box[3]]];
    const d = (c) => (c[0] - x) ** 2 + (c[1] - y) ** 2;
    return corners.reduce((best, c) => (d(c) < d(best) ? c : best));
  }

  function points(view, list) {
    return list.map((p) => view.at(p).map(f1).join(",")).join(" ");
  }

  function drawWorld(state) {
    const svg = $("world");
    updates += 1;
    svg.dataset.seq = String(updates);
    svg.dataset.frame = state.frame || "";
    const note = $("note");
    note.hidden = !state.note;
    note.textContent = state.note || "";
    const waiting = $("waiting");
    waiting.hidden = !state.error;
    waiting.textContent = state.error ? `waiting: ${state.error}` : "";
    $("title").textContent = `${state.title} (fixed frame: ${state.frame})`;
    if (state.error) return; // keep the last picture (if any) under the message

    const view = makeView(grow(state.bounds, state.frame));
    const height = view.height + TOP + BOTTOM;
    svg.setAttribute("height", height);
    svg.setAttribute("viewBox", `0 0 ${WIDTH} ${height}`);
    $("background").setAttribute("height", height);

    const obstacles = $("obstacles");
    clear(obstacles);
    for (const polygon of state.polygons) {
      el("polygon", { class: "obstacle", points: points(view, polygon), fill: "#bbbbbb",
        stroke: "#555555" }, obstacles);
    }
    for (const [a, b] of state.segments) {
      const [ax, ay] = view.at(a);
      const [bx, by] = view.at(b);
      el("line", { class: "obstacle", x1: f1(ax), y1: f1(ay), x2: f1(bx), y2: f1(by),
        stroke: "#555555", "stroke-width": 3 }, obstacles);
    }
    for (const [x, y, r] of state.circles) {
      const [cx, cy] = view.at([x, y]);
      el("circle", { class: "obstacle", cx: f1(cx), cy: f1(cy), r: f1(r * view.scale),
        fill: "#bbbbbb", stroke: "#555555" }, obstacles);
    }

    const scan = $("scan");
    clear(scan);
    for (const p of state.scan) {
      const [x, y] = view.at(p);
      el("circle", { class: "scan-point", cx: f1(x), cy: f1(y), r: 2, fill: "#00bcd4" }, scan);
    }
    scan.dataset.count = String(state.scan.length);

    const paths = $("paths");
    clear(paths);
    state.paths.forEach((path, number) => {
      if (path.points.length > 1) {
        el("polyline", { class: "path", "data-topic": path.topic, "data-count": path.points.length,
          points: points(view, path.points), fill: "none",
          stroke: PATH_COLOURS[number % PATH_COLOURS.length], "stroke-width": 2 }, paths);
      }
    });

    const footprints = $("footprints");
    clear(footprints);
    for (const footprint of state.footprints) {
      // opaque, as in the PNG
      el("polygon", { class: "footprint", points: points(view, footprint), fill: "#ffd54f",
        stroke: "#333333" }, footprints);
    }
    drawFrames(state, view);
  }

  function drawFrames(state, view) {
    const frames = $("frames");
    clear(frames);
    const robots = new Map(state.robots.map((r) => [`${r.topic} pose`, r]));
    const origins = state.frames.map((f) => view.at([f.x, f.y]));
    // sans-serif at 11 px: about 0.62 em per character, 13 px from top to bottom
    const labels = placeLabels(origins, state.frames.map((f) => [0.62 * 11 * f.name.length, 13]));
    let first = true;
    state.frames.forEach((frame, i) => {
      const [ox, oy] = origins[i];
      const attrs = { class: "frame", "data-name": frame.name, "data-x": frame.x.toFixed(3),
        "data-y": frame.y.toFixed(3), "data-yaw": frame.yaw.toFixed(3) };
      const robot = robots.get(frame.name);
      if (robot !== undefined) {
        attrs.class = "frame robot";
        attrs["data-topic"] = robot.topic;
        if (first) attrs.id = "robot";
        first = false;
      }
      const g = el("g", attrs, frames);
      const c = Math.cos(frame.yaw);
      const s = Math.sin(frame.yaw);
      // screen y points down: the frame's +y axis is drawn upwards
      el("line", { class: "axis-x", x1: f1(ox), y1: f1(oy), x2: f1(ox + AXIS_PX * c),
        y2: f1(oy - AXIS_PX * s), stroke: "red", "stroke-width": 2 }, g);
      el("line", { class: "axis-y", x1: f1(ox), y1: f1(oy), x2: f1(ox - AXIS_PX * s),
        y2: f1(oy - AXIS_PX * c), stroke: "green", "stroke-width": 2 }, g);
      const box = labels[i];
      if (moved(box, [ox, oy], 13)) {
        const [nx, ny] = nearestCorner(box, [ox, oy]);
        el("line", { x1: f1(ox), y1: f1(oy), x2: f1(nx), y2: f1(ny), stroke: "#999999",
          "stroke-width": 1 }, g);
      }
      const text = el("text", { x: f1(box[0]), y: f1(box[3] - 2), "font-family": "sans-serif",
        "font-size": 11 }, g);
      text.textContent = frame.name;
    });
  }

  // --- the graph ---------------------------------------------------------------------------

  const COLUMN_GAP = 70;
  const ROW_GAP = 16;
  const MARGIN = 16;

  function vertices(graph) {
    const list = graph.nodes.map((n) => ({
      id: `n:${n.name}`, kind: "node", name: n.name,
      lines: [n.count === 1 ? n.name : `${n.name} (x${n.count}, duplicate name)`], marks: [],
    }));
    for (const c of graph.channels) {
      const lines = c.marks.length ? [c.name, `[${c.marks.join(", ")}]`] : [c.name];
      list.push({ id: `${c.kind === "topic" ? "t" : "s"}:${c.name}`, kind: c.kind, name: c.name,
        lines, marks: c.marks });
    }
    for (const v of list) {
      const widest = Math.max(...v.lines.map((line) => line.length));
      v.w = Math.max(60, 6.4 * widest + (v.kind === "node" ? 34 : 18));
      v.h = 14 * v.lines.length + (v.kind === "node" ? 16 : 10);
    }
    return list;
  }

  function edgesOf(graph) {
    const edges = [];
    for (const c of graph.channels) {
      const id = `${c.kind === "topic" ? "t" : "s"}:${c.name}`;
      for (const s of c.sources) edges.push({ from: `n:${s}`, to: id, kind: c.kind });
      for (const s of c.sinks) edges.push({ from: id, to: `n:${s}`, kind: c.kind });
    }
    return edges;
  }

  // Columns by longest path from the sources, back edges of cycles left out of the ranking.
  function rank(list, edges) {
    const out = new Map(list.map((v) => [v.id, []]));
    const incoming = new Map(list.map((v) => [v.id, 0]));
    for (const e of edges) {
      out.get(e.from).push(e.to);
      incoming.set(e.to, incoming.get(e.to) + 1);
    }
    const state = new Map();
    const order = [];
    const forward = [];
    const visit = (v) => {
      state.set(v, 1);
      for (const w of out.get(v)) {
        if (state.get(w) === 1) continue; // a back edge: it closes a cycle
        forward.push([v, w]);
        if (!state.has(w)) visit(w);
      }
      state.set(v, 2);
      order.push(v);
    };
    const starts = list.map((v) => v.id).sort((a, b) => incoming.get(a) - incoming.get(b));
    for (const v of starts) if (!state.has(v)) visit(v);
    const ranks = new Map(list.map((v) => [v.id, 0]));
    const next = new Map(list.map((v) => [v.id, []]));
    for (const [v, w] of forward) next.get(v).push(w);
    for (const v of order.reverse()) {
      for (const w of next.get(v)) ranks.set(w, Math.max(ranks.get(w), ranks.get(v) + 1));
    }
    return ranks;
  }

  function drawGraph(graph) {
    const list = vertices(graph);
    const edges = edgesOf(graph);
    const ranks = rank(list, edges);
    const columns = [];
    for (const v of list) (columns[ranks.get(v.id)] ||= []).push(v);
    const byId = new Map(list.map((v) => [v.id, v]));
    const preds = new Map(list.map((v) => [v.id, []]));
    for (const e of edges) preds.get(e.to).push(e.from);
    const filled = columns.filter(Boolean);
    const extent = (column) => column.reduce((sum, v) => sum + v.h + ROW_GAP, -ROW_GAP);
    const tallest = Math.max(0, ...filled.map(extent));
    let x = MARGIN;
    for (const column of filled) {
      column.sort((a, b) => {
        const centre = (v) => {
          const ys = preds.get(v.id).map((p) => byId.get(p).y).filter((y) => y !== undefined);
          return ys.length ? ys.reduce((s, y) => s + y, 0) / ys.length : Infinity;
        };
        return centre(a) - centre(b) || a.name.localeCompare(b.name);
      });
      const width = Math.max(...column.map((v) => v.w));
      let y = MARGIN + (tallest - extent(column)) / 2; // columns centred on the tallest
      for (const v of column) {
        v.x = x + (width - v.w) / 2;
        v.y = y + v.h / 2;
        y += v.h + ROW_GAP;
      }
      x += width + COLUMN_GAP;
    }
    const svg = $("graph");
    const width = Math.max(200, x - COLUMN_GAP + MARGIN);
    const height = Math.max(100, tallest + 2 * MARGIN);
    svg.setAttribute("width", width);
    svg.setAttribute("height", height);
    svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
    const topics = list.filter((v) => v.kind !== "node").length;
    svg.dataset.nodes = String(list.length - topics);
    svg.dataset.topics = String(topics);
    $("graph-empty").hidden = list.length > 0;

    const edgeLayer = $("graph-edges");
    clear(edgeLayer);
    for (const e of edges) {
      const a = byId.get(e.from);
      const b = byId.get(e.to);
      const [ax, ay, bx, by] = [a.x + a.w, a.y, b.x, b.y];
      const bend = Math.max(30, Math.abs(bx - ax) / 2);
      el("path", { class: "graph-edge", "data-from": e.from, "data-to": e.to,
        d: `M ${f1(ax)} ${f1(ay)} C ${f1(ax + bend)} ${f1(ay)} ${f1(bx - bend)} ${f1(by)} ` +
          `${f1(bx)} ${f1(by)}`,
        fill: "none", stroke: "#444444", "stroke-width": 1.2, "marker-end": "url(#arrow)",
        "stroke-dasharray": e.kind === "topic" ? "none" : "5 3" }, edgeLayer);
    }
    const vertexLayer = $("graph-vertices");
    clear(vertexLayer);
    for (const v of list) drawVertex(vertexLayer, v);
  }

  function drawVertex(layer, v) {
    const kind = v.kind === "node" ? "graph-node" : `graph-${v.kind === "topic" ? "topic" : "service"}`;
    const g = el("g", { class: kind, "data-name": v.name, "data-marks": v.marks.join(",") }, layer);
    const loose = v.marks.includes("dead sink") || v.marks.includes("no server");
    const colour = loose ? "#d62728" : v.marks.includes("leaf") ? "#ff7f0e" : "#333333";
    if (v.kind === "node") {
      el("ellipse", { cx: f1(v.x + v.w / 2), cy: f1(v.y), rx: f1(v.w / 2), ry: f1(v.h / 2),
        fill: "#e8f0fb", stroke: colour }, g);
    } else if (v.kind === "topic") {
      el("rect", { x: f1(v.x), y: f1(v.y - v.h / 2), width: f1(v.w), height: f1(v.h),
        fill: "white", stroke: colour, "stroke-width": loose || v.marks.includes("leaf") ? 1.6 : 1 }, g);
    } else {
      const [cx, cy, hw, hh] = [v.x + v.w / 2, v.y, v.w / 2, v.h / 2 + 4];
      el("polygon", { points: `${f1(cx - hw)},${f1(cy)} ${f1(cx)},${f1(cy - hh)} ` +
        `${f1(cx + hw)},${f1(cy)} ${f1(cx)},${f1(cy + hh)}`, fill: "white", stroke: colour }, g);
    }
    v.lines.forEach((line, i) => {
      const text = el("text", { x: f1(v.x + v.w / 2), "text-anchor": "middle",
        y: f1(v.y - (v.lines.length - 1) * 7 + i * 14 + 4) }, g);
      text.textContent = line;
    });
  }

  // --- tabs and the event stream -------------------------------------------------------------

  function showTab() {
    const tab = location.hash === "#graph" ? "graph" : "world";
    for (const name of ["world", "graph"]) {
      $(`panel-${name}`).hidden = name !== tab;
      $(`tab-${name}`).classList.toggle("active", name === tab);
    }
  }

  function status(state, text) {
    const node = $("status");
    node.dataset.state = state;
    node.textContent = text;
  }

  // the newest message's stamp: a wall-clock time, or seconds of sim time
  function when(stampNs) {
    if (!stampNs) return "";
    const seconds = stampNs / 1e9;
    if (seconds > 1e9) return ` · ${new Date(seconds * 1000).toLocaleTimeString()}`;
    return ` · t = ${seconds.toFixed(1)} s`;
  }

  function drawState(state) {
    drawWorld(state);
    status("live", `live${when(state.stamp_ns)}`);
  }

  window.addEventListener("hashchange", showTab);
  showTab();
  const initial = JSON.parse($("initial").textContent || "null");
  if (initial && initial.state) drawWorld(initial.state);
  if (initial && initial.graph) drawGraph(initial.graph);
  const events = new EventSource("events");
  events.addEventListener("open", () => status("live", "live"));
  events.addEventListener("error", () => status("lost", "connection lost, retrying…"));
  events.addEventListener("state", (event) => drawState(JSON.parse(event.data)));
  events.addEventListener("graph", (event) => drawGraph(JSON.parse(event.data)));
})();
