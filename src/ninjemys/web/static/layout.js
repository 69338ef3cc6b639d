// Layered ("Sugiyama-lite") layout for small directed graphs, like dot's rankdir=LR in rqt_graph.
// layoutGraph(vertices, edges, opts) -> {pos: Map(id -> {x, y, w, h}), width, height}
// vertices: [{id, w, h, group}], edges: [{source, target}]
"use strict";

function layoutGraph(vertices, edges, opts) {
  const o = Object.assign({ colGap: 70, rowGap: 18, margin: 30 }, opts || {});
  const ids = vertices.map((v) => v.id);
  const byId = new Map(vertices.map((v) => [v.id, v]));
  const out = new Map(ids.map((id) => [id, []]));
  const inc = new Map(ids.map((id) => [id, []]));
  for (const e of edges) {
    if (!byId.has(e.source) || !byId.has(e.target) || e.source === e.target) continue;
    out.get(e.source).push(e.target);
    inc.get(e.target).push(e.source);
  }
  // 1. break cycles: drop edges that close a cycle in a DFS from sources (deterministic by id)
  const state = new Map();
  const dag = new Map(ids.map((id) => [id, []]));
  const order = [...ids].sort((a, b) => inc.get(a).length - inc.get(b).length || (a < b ? -1 : 1));
  for (const root of order) {
    if (state.has(root)) continue;
    const stack = [[root, 0]];
    state.set(root, 1);
    while (stack.length) {
      const top = stack[stack.length - 1];
      const [v, i] = top;
      const succ = out.get(v);
      if (i < succ.length) {
        top[1] += 1;
        const w = succ[i];
        const s = state.get(w);
        if (s === 1) continue; // back edge: ignore for ranking
        dag.get(v).push(w);
        if (!s) { state.set(w, 1); stack.push([w, 0]); }
      } else {
        state.set(v, 2);
        stack.pop();
      }
    }
  }
  // 2. longest-path ranks over the DAG
  const rank = new Map();
  const indeg = new Map(ids.map((id) => [id, 0]));
  for (const [, ws] of dag) for (const w of ws) indeg.set(w, indeg.get(w) + 1);
  const queue = ids.filter((id) => indeg.get(id) === 0).sort();
  for (const id of queue) rank.set(id, 0);
  while (queue.length) {
    const v = queue.shift();
    for (const w of dag.get(v)) {
      rank.set(w, Math.max(rank.get(w) || 0, rank.get(v) + 1));
      indeg.set(w, indeg.get(w) - 1);
      if (indeg.get(w) === 0) queue.push(w);
    }
  }
  // 3. order inside each rank: by group, then barycentre of neighbours in the previous rank
  const layers = [];
  for (const id of ids) {
    const r = rank.get(id) || 0;
    (layers[r] = layers[r] || []).push(id);
  }
  const index = new Map();
  const groupKey = (id) => byId.get(id).group || "";
  layers.forEach((layer) => {
    layer.sort((a, b) => (groupKey(a) < groupKey(b) ? -1 : groupKey(a) > groupKey(b) ? 1 : a < b ? -1 : 1));
    layer.forEach((id, i) => index.set(id, i));
  });
  for (let pass = 0; pass < 4; pass++) {
    for (let r = 1; r < layers.length; r++) {
      const bary = (id) => {
        const ns = inc.get(id).filter((p) => rank.get(p) < r);
        return ns.length ? ns.reduce((s, p) => s + index.get(p), 0) / ns.length : index.get(id);
      };
      const groupBary = new Map();
      for (const id of layers[r]) {
        const g = groupKey(id);
        const cur = groupBary.get(g) || [0, 0];
        groupBary.set(g, [cur[0] + bary(id), cur[1] + 1]);
      }
      const gb = (id) => { const [s, n] = groupBary.get(groupKey(id)); return s / n; };
      layers[r].sort((a, b) => gb(a) - gb(b) || (groupKey(a) < groupKey(b) ? -1 : groupKey(a) > groupKey(b) ? 1 : 0) || bary(a) - bary(b));
      layers[r].forEach((id, i) => index.set(id, i));
    }
  }
  // 4. coordinates: columns left to right, each column centred vertically
  const colWidth = layers.map((layer) => Math.max(...layer.map((id) => byId.get(id).w)));
  const colHeight = layers.map((layer) => layer.reduce((s, id) => s + byId.get(id).h + o.rowGap, -o.rowGap));
  const height = Math.max(0, ...colHeight) + 2 * o.margin;
  const pos = new Map();
  let x = o.margin;
  layers.forEach((layer, r) => {
    let y = o.margin + (height - 2 * o.margin - colHeight[r]) / 2;
    for (const id of layer) {
      const v = byId.get(id);
      pos.set(id, { x: x + colWidth[r] / 2, y: y + v.h / 2, w: v.w, h: v.h });
      y += v.h + o.rowGap;
    }
    x += colWidth[r] + o.colGap;
  });
  return { pos, width: x - o.colGap + o.margin, height };
}
