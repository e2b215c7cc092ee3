// app/lab/page/serve_page.js -- the page of `cdlab serve`: the live picture (the off-screen
// renderer's PNG), a control for every demo command (each sent as one POST /api/command), the
// HUD, the current frame's flagged and confirmed pairs by body name (a click on one shows the
// frames it was flagged and confirmed in), the selected body, and a timeline of pairs per frame
// growing as the session plays. Every name shown goes in as text,
// never as markup.
(function () {
  "use strict";
  const data = JSON.parse(document.getElementById("serve-data").textContent);
  const root = document.getElementById("live");

  function el(tag, attrs, children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") e.textContent = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v);
    }
    for (const c of children || []) e.appendChild(c);
    return e;
  }

  // --- layout -------------------------------------------------------------------------------
  const picture = el("img", { id: "frame-view", alt: "the current frame", width: data.width,
                              height: data.height });
  const pictureBox = el("div", { class: "picture" }, [picture]);
  const hud = el("pre", { id: "hud", class: "meta" });
  const message = el("p", { id: "message", class: "hint", role: "status" });
  const controls = el("div", { id: "controls" });
  const pairs = el("div", { id: "pairs" });
  const history = el("div", { id: "pair-history", class: "detail", hidden: "" });
  const selected = el("div", { id: "selected", class: "detail", hidden: "" });
  const chartBox = el("div", { class: "chart-box" }, [el("canvas", { id: "timeline" })]);
  root.appendChild(el("div", { class: "pause-grid" }, [
    pictureBox,
    el("div", { class: "pause-side" }, [controls, message, hud, selected, history, pairs]),
  ]));
  root.appendChild(el("h2", { text: "Pairs per frame" }));
  root.appendChild(chartBox);

  let state = null;  // the newest state.json
  let version = 0;   // its picture's version

  // --- commands -------------------------------------------------------------------------------
  async function send(command) {
    try {
      const r = await fetch("/api/command", {
        method: "POST", headers: { "Content-Type": "application/json" },
        body: JSON.stringify(command),
      });
      const a = await r.json();
      message.textContent = a.ok ? "applied at frame " + a.at_frame + ", now at frame " + a.frame
                                 : "refused: " + a.error;
      message.className = a.ok ? "hint" : "missing";
    } catch (e) {
      message.textContent = "the server did not answer: " + e;
      message.className = "missing";
    }
  }

  function button(label, command, id) {
    return el("button", { type: "button", id: id || "", onclick: () => send(command()),
                          text: label });
  }

  const play = el("div", { class: "row" }, [
    button("play", () => ({ play: true }), "cmd-play"),
    button("pause", () => ({ pause: true }), "cmd-pause"),
    button("-10", () => ({ step: -10 }), "cmd-back10"),
    button("-1", () => ({ step: -1 }), "cmd-back"),
    button("+1", () => ({ step: 1 }), "cmd-step"),
    button("+10", () => ({ step: 10 }), "cmd-step10"),
    button("dump", () => ({ dump: true }), "cmd-dump"),
  ]);
  const seek = el("input", { id: "seek", type: "number", min: 0, value: 0, style: "width:6em" });
  const seekRow = el("div", { class: "row" }, [
    el("label", { text: "frame " }, [seek]),
    button("seek", () => ({ seek: { frame: Number(seek.value) } }), "cmd-seek"),
  ]);
  const speed = el("select", { id: "speed" });
  for (const s of [0.0625, 0.125, 0.25, 0.5, 1, 2, 4, 8, 16]) {
    speed.appendChild(el("option", { value: s, text: s + "x" }));
  }
  speed.value = "1";
  speed.addEventListener("change", () => send({ speed: Number(speed.value) }));
  const phase = el("select", { id: "broadphase" });
  for (const name of data.broadphases) phase.appendChild(el("option", { value: name, text: name }));
  phase.addEventListener("change", () => send({ broadphase: phase.value }));
  const layerBoxes = {};
  const layers = el("fieldset", { id: "layers" }, [el("legend", { text: "layers" })]);
  for (const name of data.layers) {
    const box = el("input", { type: "checkbox", id: "layer-" + name });
    box.addEventListener("change", () => send(box.checked ? { show: [name] } : { hide: [name] }));
    layerBoxes[name] = box;
    layers.appendChild(el("label", {}, [box, document.createTextNode(name + " ")]));
  }
  const camera = el("div", { class: "row" }, [
    document.createTextNode("camera "),
    button("\u2190", () => ({ camera: { orbit: [-15, 0] } }), "cam-left"),
    button("\u2192", () => ({ camera: { orbit: [15, 0] } }), "cam-right"),
    button("\u2191", () => ({ camera: { orbit: [0, 10] } }), "cam-up"),
    button("\u2193", () => ({ camera: { orbit: [0, -10] } }), "cam-down"),
    button("zoom in", () => ({ camera: { zoom: 1.25 } }), "cam-in"),
    button("zoom out", () => ({ camera: { zoom: 0.8 } }), "cam-out"),
    button("follow selected", () => ({ camera: { follow: selectedName() || "none" } }),
           "cam-follow"),
    button("reset", () => ({ camera: { reset: true } }), "cam-reset"),
  ]);
  controls.appendChild(play);
  controls.appendChild(seekRow);
  controls.appendChild(el("div", { class: "row" }, [
    el("label", { text: "speed " }, [speed]), document.createTextNode(" "),
    el("label", { text: "broad phase " }, [phase]),
    button("select none", () => ({ select: "none" }), "cmd-select-none"),
  ]));
  controls.appendChild(layers);
  controls.appendChild(camera);

  function selectedName() { return state && state.session.selected; }

  // A click on the picture selects the body whose rectangle holds the point (the smallest).
  picture.addEventListener("click", (ev) => {
    if (!state) return;
    const box = picture.getBoundingClientRect();
    const x = (ev.clientX - box.left) * data.width / box.width;
    const y = (ev.clientY - box.top) * data.height / box.height;
    let best = -1, bestArea = Infinity;
    state.session.rects.forEach((r, i) => {
      if (!r || x < r[0] || x > r[2] || y < r[1] || y > r[3]) return;
      const area = (r[2] - r[0]) * (r[3] - r[1]);
      if (area < bestArea) { best = i; bestArea = area; }
    });
    send({ select: best < 0 ? "none" : state.bodies[best].name });
  });

  // --- what the state shows -------------------------------------------------------------------
  // One pair's history: the frame ranges it was flagged and confirmed in, each a link to seek.
  async function showHistory(a, b) {
    try {
      const r = await fetch("/api/pair.json?a=" + encodeURIComponent(a) + "&b=" +
                            encodeURIComponent(b));
      const h = await r.json();
      if (!r.ok) throw new Error(h.error);
      const ranges = (list) => list.length === 0 ? [document.createTextNode("never")] :
        list.map(([first, last]) => el("button", {
          type: "button", class: "range", text: first === last ? String(first) : first + "\u2013" + last,
          onclick: () => send({ seek: { frame: first } }) }));
      history.replaceChildren(
        el("h3", { text: "pair " + h.a + " \u2013 " + h.b }),
        el("p", { class: "hint", text: "frames 0.." + (h.frames - 1) + " " +
                                        (data.replay ? "of the recording" : "reached so far") }),
        el("dl", {}, [
          el("dt", { text: "flagged in frames" }), el("dd", { class: "flagged-ranges" }, ranges(h.flagged)),
          el("dt", { text: "confirmed in frames" }), el("dd", { class: "colliding-ranges" }, ranges(h.colliding)),
        ]));
      history.hidden = false;
    } catch (e) {
      message.textContent = "no history: " + e.message;
      message.className = "missing";
    }
  }

  function pairList(title, list, id) {
    const names = (p) => state.bodies[p[0]].name + " \u2013 " + state.bodies[p[1]].name;
    const items = list.slice(0, 200).map((p) => el("li", {
      text: names(p), class: "pair-row", title: "the frames this pair was flagged and confirmed in",
      onclick: () => showHistory(state.bodies[p[0]].name, state.bodies[p[1]].name) }));
    const more = list.length > 200 ? [el("li", { text: "and " + (list.length - 200) + " more" })]
                                   : [];
    return el("div", { id: id }, [el("h3", { text: title + " (" + list.length + ")" }),
                                   el("ul", {}, items.concat(more))]);
  }

  function showState() {
    const s = state.session;
    hud.textContent = s.hud;
    seek.max = s.last_frame;
    if (document.activeElement !== seek) seek.value = s.frame;
    if (document.activeElement !== phase) phase.value = s.broadphase;
    if (document.activeElement !== speed) speed.value = String(s.speed);
    for (const [name, box] of Object.entries(layerBoxes)) box.checked = s.layers.includes(name);
    pairs.replaceChildren(pairList("confirmed", state.colliding_pairs, "colliding-pairs"),
                          pairList("flagged", state.flagged_pairs, "flagged-pairs"));
    if (s.selected === null) {
      selected.hidden = true;
    } else {
      const i = state.bodies.findIndex((b) => b.name === s.selected);
      const b = state.bodies[i];
      const partners = (list) => list.filter((p) => p[0] === i || p[1] === i)
        .map((p) => state.bodies[p[0] === i ? p[1] : p[0]].name).join(", ") || "none";
      selected.replaceChildren(
        el("h3", { text: "selected: " + b.name + " (" + b.shape + ")" }),
        el("dl", {}, [
          el("dt", { text: "state" }), el("dd", { text: b.state }),
          el("dt", { text: "position" }),
          el("dd", { text: b.position.map((v) => v.toPrecision(6)).join(", ") }),
          el("dt", { text: "confirmed with" }), el("dd", { text: partners(state.colliding_pairs) }),
          el("dt", { text: "flagged with" }), el("dd", { text: partners(state.flagged_pairs) }),
        ]));
      selected.hidden = false;
    }
    const r = s.selected === null ? null : s.rects[state.bodies.findIndex((b) => b.name === s.selected)];
    for (const o of pictureBox.querySelectorAll(".outline")) o.remove();
    if (r) {
      pictureBox.appendChild(el("div", { class: "outline", style:
        "left:" + (100 * r[0] / data.width) + "%;top:" + (100 * r[1] / data.height) +
        "%;width:" + (100 * (r[2] - r[0]) / data.width) + "%;height:" +
        (100 * (r[3] - r[1]) / data.height) + "%" }));
    }
  }

  // Long polls: each answer is the state of a newer picture, whose PNG is then shown.
  async function follow() {
    for (;;) {
      try {
        const r = await fetch("/api/state.json?after=" + version);
        const next = await r.json();
        if (next.session && next.session.version !== version) {
          state = next;
          version = next.session.version;
          picture.src = "/api/frame.png?version=" + version;
          showState();
        }
      } catch (e) {
        message.textContent = "lost the server (" + e + "); retrying";
        message.className = "missing";
        await new Promise((done) => setTimeout(done, 1000));
      }
    }
  }

  // The timeline: flagged and confirmed pairs of every frame reached, fetched once a second.
  const chart = new Chart(document.getElementById("timeline"), {
    type: "line",
    data: { labels: [], datasets: [
      { label: "flagged", data: [], borderColor: "#e6b000", pointRadius: 0 },
      { label: "confirmed", data: [], borderColor: "#dc2828", pointRadius: 0 },
    ] },
    options: { animation: false, responsive: true, maintainAspectRatio: false,
               scales: { x: { title: { display: true, text: "frame" } },
                         y: { title: { display: true, text: "pairs" }, beginAtZero: true } } },
  });
  let rows = 0;
  async function grow() {
    try {
      const r = await fetch("/api/timeline.json?from=" + rows);
      const list = await r.json();
      for (const row of list) {
        chart.data.labels.push(row.frame);
        chart.data.datasets[0].data.push(row.flagged);
        chart.data.datasets[1].data.push(row.colliding);
      }
      rows += list.length;
      if (list.length) chart.update();
    } catch (e) { /* the state poll says so */ }
    setTimeout(grow, 1000);
  }

  follow();
  grow();
})();
