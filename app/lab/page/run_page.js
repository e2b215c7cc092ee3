// app/lab/page/run_page.js -- the script of a run's index.html (app/lab/run_html.cpp): draws
// the timeline from the page's JSON (#run-data) with Chart.js, keeps a cursor on the frame the
// video shows, and lists each pause picture's bodies and pairs. Marks what it drew with
// data-rendered="1" (and the plot area as data-rect) for the tests.
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('run-data').textContent);
  const timeline = data.timeline;
  const frameCount = timeline.frame.length;
  const fps = data.fps > 0 ? data.fps : 30;
  const video = document.getElementById('video');
  const readout = document.getElementById('readout');
  const state = { frame: 0, held: false };

  // The video holds each pause picture hold_frames frames after its frame: video frame v shows
  // run frame f with start[f] <= v < start[f + 1].
  const pauseFrames = new Set(data.pauses.map(function (p) { return p.frame; }));
  const start = new Array(frameCount);
  let v = 0;
  for (let f = 0; f < frameCount; ++f) {
    start[f] = v;
    v += 1 + (pauseFrames.has(f) ? data.hold_frames : 0);
  }

  function frameAtVideoTime(t) {
    const vf = Math.floor(t * fps + 1e-6);
    let lo = 0, hi = frameCount - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (start[mid] <= vf) lo = mid; else hi = mid - 1;
    }
    return { frame: lo, held: vf > start[lo] };
  }

  // Without a video, the frames' PNGs beside the page (when the run wrote them) follow the cursor.
  let frameView = document.getElementById('frame-view');
  function frameFile(f) { return 'frame_' + String(f).padStart(5, '0') + '.png'; }

  function showFrame(frame, held) {
    if (frame === state.frame && held === state.held) return;
    state.frame = frame;
    state.held = held;
    if (frameView) frameView.src = frameFile(frame);
    const i = Math.max(0, Math.min(frameCount - 1, frame));
    readout.textContent = 'frame ' + frame + ' of ' + (frameCount - 1) + ' \u00b7 t = ' +
        Number(timeline.time[i]).toPrecision(4) + ' s \u00b7 ' + timeline.flagged[i] +
        ' flagged, ' + timeline.colliding[i] + ' confirmed' + (held ? ' \u00b7 pause picture' : '');
    charts.forEach(function (c) { c.draw(); });
  }

  function seekTo(frame) {
    const f = Math.max(0, Math.min(frameCount - 1, Math.round(frame)));
    if (video && !video.error && !video.hidden) video.currentTime = (start[f] + 0.5) / fps;
    showFrame(f, false);
  }

  // The cursor (the frame on screen) and the pause frames, over the datasets.
  const cursorPlugin = {
    id: 'cursor',
    afterDatasetsDraw: function (chart) {
      const ctx = chart.ctx, area = chart.chartArea, x = chart.scales.x;
      ctx.save();
      ctx.setLineDash([4, 4]);
      ctx.strokeStyle = '#999999';
      ctx.lineWidth = 1;
      pauseFrames.forEach(function (f) {
        const px = x.getPixelForValue(f);
        ctx.beginPath(); ctx.moveTo(px, area.top); ctx.lineTo(px, area.bottom); ctx.stroke();
      });
      ctx.setLineDash([]);
      ctx.strokeStyle = '#1f4fd8';
      ctx.lineWidth = 2;
      const px = x.getPixelForValue(state.frame);
      ctx.beginPath(); ctx.moveTo(px, area.top); ctx.lineTo(px, area.bottom); ctx.stroke();
      ctx.restore();
    }
  };

  function series(values) {
    return values.map(function (y, i) { return { x: timeline.frame[i], y: y }; });
  }

  // The plot area (inside the axes) in page pixels, as data-rect="x,y,width,height".
  function markPlotArea(canvas, chart) {
    const r = canvas.getBoundingClientRect(), a = chart.chartArea;
    canvas.dataset.rect = [r.left + window.scrollX + a.left, r.top + window.scrollY + a.top,
                           a.right - a.left, a.bottom - a.top].map(Math.round).join(',');
  }

  function lineChart(canvas, title, yTitle, datasets, stacked) {
    const chart = new Chart(canvas, {
      type: 'line',
      data: { datasets: datasets },
      options: {
        animation: false, parsing: false, normalized: true, responsive: true,
        maintainAspectRatio: false,
        interaction: { mode: 'index', intersect: false },
        elements: { point: { radius: 0 }, line: { borderWidth: 2 } },
        scales: {
          x: { type: 'linear', min: 0, max: Math.max(1, frameCount - 1),
               ticks: { precision: 0 }, title: { display: true, text: 'frame' } },
          // One width for every chart's y axis, so that their frames line up under each other.
          y: { beginAtZero: true, stacked: stacked, grace: '5%',
               title: { display: true, text: yTitle },
               afterFit: function (scale) { scale.width = 72; } }
        },
        plugins: { title: { display: true, text: title }, legend: { position: 'top' },
                   decimation: { enabled: false } },
        onClick: function (event, elements, c) {
          seekTo(c.scales.x.getValueForPixel(event.x));
        }
      },
      plugins: [cursorPlugin]
    });
    canvas.dataset.rendered = '1';
    markPlotArea(canvas, chart);
    return chart;
  }

  // Stage colours: a qualitative palette (Okabe and Ito, "Color Universal Design", 2008).
  const stageColours = { integrate: '#999999', volumes: '#56b4e9', broadphase: '#009e73',
                         narrowphase: '#cc79a7', ccd: '#0072b2', response: '#d55e00' };
  const charts = [];
  charts.push(lineChart(document.getElementById('pairs-chart'), 'pairs per frame', 'pairs', [
    // Confirmed pairs are drawn over flagged ones (a lower order is drawn later): where every
    // flagged pair is confirmed the lines coincide and the red one shows.
    { label: 'flagged (broad phase)', data: series(timeline.flagged), borderColor: '#e6b000',
      backgroundColor: '#e6b000', order: 1 },
    { label: 'confirmed (narrow phase)', data: series(timeline.colliding),
      borderColor: '#dc2828', backgroundColor: '#dc2828', order: 0 }
  ], false));
  charts.push(lineChart(document.getElementById('stages-chart'),
      'stage time per frame (wall clock, stacked; frame 0 is the scene as loaded)', 'ms',
      Object.keys(timeline.stage_ms).map(function (name) {
        return { label: name, data: series(timeline.stage_ms[name]), fill: true,
                 borderColor: stageColours[name], backgroundColor: stageColours[name] + '99' };
      }), true));
  // Frame 0 evaluates the loaded scene from scratch (every volume fitted, every pair new) and
  // can cost a hundred steps: the axis is scaled to the steps after it, frame 0 runs off the top.
  if (frameCount > 2) {
    const later = Math.max.apply(null, timeline.step_ms.slice(1));
    if (later > 0 && timeline.step_ms[0] > 1.5 * later) {
      charts[1].options.scales.y.max = 1.1 * later;
      charts[1].update('none');
    }
  }

  function noVideo(reason) {
    const message = document.getElementById('no-video');
    message.textContent = 'no video: ' + reason;
    message.hidden = false;
    if (video) video.hidden = true;
    if (!frameView && data.frames_written && frameCount > 0) {
      frameView = document.createElement('img');
      frameView.id = 'frame-view';
      frameView.alt = 'the frame at the cursor';
      frameView.src = frameFile(Math.max(0, state.frame));
      message.after(frameView);
    }
  }

  if (video) {
    const following = function () {
      const at = frameAtVideoTime(video.currentTime);
      showFrame(at.frame, at.held);
      if (!video.paused && !video.ended) window.requestAnimationFrame(following);
    };
    video.addEventListener('timeupdate', following);
    video.addEventListener('seeked', following);
    video.addEventListener('play', following);
    video.addEventListener('loadedmetadata', function () {
      video.dataset.duration = String(video.duration);
    });
    const failed = function () { noVideo('cannot load ' + data.video); };
    video.addEventListener('error', failed);
    if (video.error || video.networkState === HTMLMediaElement.NETWORK_NO_SOURCE) failed();
  }
  state.frame = -1;
  showFrame(0, false);
  // Left and right arrows step one frame (the video's own keys when it has the focus).
  document.addEventListener('keydown', function (event) {
    if (event.target === video || event.altKey || event.ctrlKey || event.metaKey) return;
    if (event.key === 'ArrowLeft' || event.key === 'ArrowRight') {
      if (video) video.pause();
      seekTo(state.frame + (event.key === 'ArrowRight' ? 1 : -1));
      event.preventDefault();
    }
  });

  function text(tag, content, cls) {
    const e = document.createElement(tag);
    if (content !== undefined) e.textContent = content;
    if (cls) e.className = cls;
    return e;
  }
  function vec(a) { return '(' + a.map(function (x) { return Number(x).toPrecision(4); }).join(', ') + ')'; }

  // The k-DOPs a pause dump holds ("kdop6", "kdop14", ...: those the scene draws), and how a
  // legend names one ("14-DOP").
  function kdopNames(dump) { return Object.keys(dump.kdop_slab_directions || {}); }
  function kdopLabel(name) { return name.slice(4) + '-DOP'; }

  // Every field of a body: pose, motion, each volume and its state.
  function bodyDetail(body, kdops) {
    const rows = [
      ['body', body.id + ' ' + (body.name || '') + ' (' + body.shape + ')'],
      ['state', body.state],
      ['position', vec(body.position)],
      ['orientation (w, x, y, z)', vec(body.orientation_wxyz)],
      ['velocity', vec(body.velocity)],
      ['angular velocity', vec(body.angular_velocity)],
      ['sphere', 'centre ' + vec(body.sphere.center) + ', radius ' +
          Number(body.sphere.radius).toPrecision(4) + ' \u2014 ' + body.volume_states.sphere],
      ['AABB', 'min ' + vec(body.aabb.min) + ', max ' + vec(body.aabb.max) + ' \u2014 ' +
          body.volume_states.aabb],
      ['OBB', 'centre ' + vec(body.obb.center) + ', half extents ' +
          vec(body.obb.half_extents) + ', axes ' + body.obb.axes.map(vec).join(' ') + ' \u2014 ' +
          body.volume_states.obb]
    ];
    kdops.forEach(function (name) {
      const kdop = body[name];
      const slabs = kdop.min.map(function (lo, i) {
        return '[' + Number(lo).toPrecision(4) + ', ' + Number(kdop.max[i]).toPrecision(4) + ']';
      });
      rows.push([kdopLabel(name), 'slabs ' + slabs.join(' ') + ' \u2014 ' +
          body.volume_states[name]]);
    });
    const dl = document.createElement('dl');
    rows.forEach(function (r) { dl.appendChild(text('dt', r[0])); dl.appendChild(text('dd', r[1])); });
    return dl;
  }

  // A button per pair, named by its bodies ("ball7\u2013ball8"; a body without a name by its id).
  function pairList(title, pairs, bodies, select) {
    const p = text('p', title + ': ' + (pairs.length ? '' : 'none'), 'pairs');
    const name = function (id) { return (bodies[id] && bodies[id].name) || String(id); };
    pairs.forEach(function (pair) {
      const b = text('button', name(pair[0]) + '\u2013' + name(pair[1]), 'pair');
      b.title = 'bodies ' + pair[0] + ' and ' + pair[1];
      b.addEventListener('click', function () { select(pair); });
      p.appendChild(b);
    });
    return p;
  }

  function pauseSection(pause) {
    const dump = pause.dump;
    const article = text('article', undefined, 'pause');
    article.id = 'pause-' + pause.frame;
    // The mesh hierarchies' volume names (world.mesh_bvh), when there are mesh bodies.
    const meshBvhs = [];
    for (const body of dump.bodies) {
      if (body.mesh_bvh !== undefined && meshBvhs.indexOf(body.mesh_bvh) < 0) {
        meshBvhs.push(body.mesh_bvh);
      }
    }
    const heading = text('h3', 'frame ' + pause.frame + ', t = ' +
        Number(dump.time).toPrecision(4) + ' s (' + dump.broadphase + ', tests ' +
        dump.broadphase_volume +
        (meshBvhs.length > 0 ? '; mesh hierarchies ' + meshBvhs.join(', ') : '') + ')');
    const jump = text('button', 'show in the video', 'jump');
    jump.addEventListener('click', function () { seekTo(pause.frame); });
    heading.appendChild(jump);
    article.appendChild(heading);
    const grid = text('div', undefined, 'pause-grid');
    // The picture with an outline over the body shown (its AABB's place in the picture).
    const picture = text('div', undefined, 'picture');
    const img = document.createElement('img');
    img.src = pause.picture;
    img.alt = 'pause picture of frame ' + pause.frame;
    img.addEventListener('error', function () {
      picture.replaceWith(text('p', 'no picture: cannot load ' + pause.picture, 'missing'));
    });
    picture.appendChild(img);
    const outlines = [];
    const outline = function (ids) {
      outlines.forEach(function (o) { o.remove(); });
      outlines.length = 0;
      ids.forEach(function (id) {
        const r = pause.rects[id];
        if (!r) return;
        const o = text('div', undefined, 'outline');
        o.style.left = (100 * r[0] / data.width) + '%';
        o.style.top = (100 * r[1] / data.height) + '%';
        o.style.width = (100 * (r[2] - r[0]) / data.width) + '%';
        o.style.height = (100 * (r[3] - r[1]) / data.height) + '%';
        picture.appendChild(o);
        outlines.push(o);
      });
    };
    grid.appendChild(picture);
    const side = text('div', undefined, 'pause-side');
    const detail = text('div', 'Hover over or click a body (in the list or in the picture) to ' +
                        'see its volumes and state.', 'detail');
    const table = document.createElement('table');
    table.className = 'bodies';
    const head = table.createTHead().insertRow();
    const kdops = kdopNames(dump);
    const columns = ['id', 'name', 'shape', 'state', 'sphere', 'AABB', 'OBB'];
    columns.concat(kdops.map(kdopLabel)).forEach(function (h) {
      head.appendChild(text('th', h));
    });
    const body = table.createTBody();
    let pinned = null;
    const show = function (row, b) {
      body.querySelectorAll('tr.highlight').forEach(function (r) { r.classList.remove('highlight'); });
      row.classList.add('highlight');
      detail.replaceChildren(bodyDetail(b, kdops));
      outline([b.id]);
    };
    // The body under the pointer: the smallest outline holding it (nearer bodies tend to be
    // larger, so the smallest is the most specific guess).
    const bodyAt = function (event) {
      const box = img.getBoundingClientRect();
      const x = (event.clientX - box.left) * data.width / box.width;
      const y = (event.clientY - box.top) * data.height / box.height;
      let best = -1, area = Infinity;
      pause.rects.forEach(function (r, id) {
        if (!r || x < r[0] || x > r[2] || y < r[1] || y > r[3]) return;
        const a = (r[2] - r[0]) * (r[3] - r[1]);
        if (a < area) { area = a; best = id; }
      });
      return best;
    };
    picture.addEventListener('mousemove', function (event) {
      const id = bodyAt(event);
      if (id >= 0) show(body.rows[id], dump.bodies[id]);
    });
    picture.addEventListener('click', function (event) {
      const id = bodyAt(event);
      if (id < 0) return;
      pinned = { row: body.rows[id], body: dump.bodies[id] };
      show(pinned.row, pinned.body);
      pinned.row.scrollIntoView({ block: 'nearest' });
    });
    picture.addEventListener('mouseleave', function () {
      if (pinned) show(pinned.row, pinned.body);
    });
    dump.bodies.forEach(function (b) {
      const row = body.insertRow();
      row.className = 'body state-' + b.state;
      row.dataset.body = String(b.id);
      const cells = [b.id, b.name, b.shape, b.state, b.volume_states.sphere, b.volume_states.aabb,
                     b.volume_states.obb];
      kdops.forEach(function (name) { cells.push(b.volume_states[name]); });
      cells.forEach(function (c) { row.appendChild(text('td', String(c))); });
      row.addEventListener('mouseenter', function () { show(row, b); });
      row.addEventListener('mouseleave', function () {
        if (pinned) {
          show(pinned.row, pinned.body);
        } else {
          row.classList.remove('highlight');
          outline([]);
        }
      });
      row.addEventListener('click', function () { pinned = { row: row, body: b }; show(row, b); });
    });
    const select = function (pair) {
      body.querySelectorAll('tr.highlight').forEach(function (r) { r.classList.remove('highlight'); });
      pair.forEach(function (id) {
        const row = body.querySelector('tr[data-body="' + id + '"]');
        if (row) row.classList.add('highlight');
      });
      detail.replaceChildren(bodyDetail(dump.bodies[pair[0]], kdops),
                             bodyDetail(dump.bodies[pair[1]], kdops));
      outline(pair);
    };
    side.appendChild(pairList('confirmed pairs', dump.colliding_pairs, dump.bodies, select));
    side.appendChild(pairList('flagged pairs', dump.flagged_pairs, dump.bodies, select));
    // The detail below the table: as it grows or shrinks (one body, a pair) the rows stay where
    // they are, so the row under the pointer stays the one shown.
    const scroll = text('div', undefined, 'table-scroll');
    scroll.appendChild(table);
    side.appendChild(scroll);
    side.appendChild(detail);
    grid.appendChild(side);
    article.appendChild(grid);
    table.dataset.rendered = '1';
    return article;
  }

  // The plot areas again whenever the layout may have moved them.
  const remark = function () {
    markPlotArea(document.getElementById('pairs-chart'), charts[0]);
    markPlotArea(document.getElementById('stages-chart'), charts[1]);
  };
  window.addEventListener('load', remark);
  window.addEventListener('resize', remark);
  if (video) video.addEventListener('loadedmetadata', remark);

  const pauses = document.getElementById('pauses');
  data.pauses.forEach(function (p) { pauses.appendChild(pauseSection(p)); });
  document.body.dataset.rendered = '1';
})();
