// app/lab/page/sweep_page.js -- the script of a sweep's report.html (app/lab/sweep_html.cpp):
// draws the charts from the page's JSON (#sweep-data) with Chart.js, and sorts the results table
// by the column whose header is clicked (numbers numerically; failed runs stay last). The URL's
// ?sort=COLUMN&order=desc sorts on opening. Marks what it drew with data-rendered="1" (and each
// chart's plot area as data-rect) for the tests.
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('sweep-data').textContent);
  const section = document.getElementById('charts');

  // The plot area (inside the axes) in page pixels, as data-rect="x,y,width,height".
  function markPlotArea(canvas, chart) {
    const r = canvas.getBoundingClientRect(), a = chart.chartArea;
    canvas.dataset.rect = [r.left + window.scrollX + a.left, r.top + window.scrollY + a.top,
                           a.right - a.left, a.bottom - a.top].map(Math.round).join(',');
  }

  // Axis numbers: three significant digits, exponents outside 1e-3..1e5.
  function tick(value) {
    const v = Number(value);
    if (v === 0) return '0';
    const a = Math.abs(v);
    return a >= 1e-3 && a < 1e5 ? String(Number(v.toPrecision(3))) : v.toExponential(1);
  }
  // A log axis labels its powers of ten only.
  function decade(value) {
    const e = Math.log10(Number(value));
    return Math.abs(e - Math.round(e)) < 1e-9 ? '1e' + Math.round(e) : '';
  }

  function barChart(spec, index) {
    const box = document.createElement('div');
    box.className = 'bar-box';
    box.style.height = (70 + 26 * spec.labels.length) + 'px';
    const canvas = document.createElement('canvas');
    canvas.id = 'chart-' + index;
    canvas.dataset.file = spec.file;
    box.appendChild(canvas);
    section.appendChild(box);
    const last = spec.labels.length - 1;
    const colours = spec.labels.map(function (l, i) {
      return spec.highlight_last && i === last ? '#ee854a' : '#4878d0';
    });
    // A log axis cannot show zero: those bars are left out (drawn as none) and said so.
    const values = spec.values.map(function (v) {
      return v === null || (spec.log_scale && !(v > 0)) ? null : v;
    });
    const chart = new Chart(canvas, {
      type: 'bar',
      data: { labels: spec.labels,
              datasets: [{ data: values, backgroundColor: colours, borderColor: colours }] },
      options: {
        indexAxis: 'y', animation: false, responsive: true, maintainAspectRatio: false,
        scales: { x: { type: spec.log_scale ? 'logarithmic' : 'linear',
                       beginAtZero: !spec.log_scale,
                       ticks: { maxRotation: 0, callback: spec.log_scale ? decade : tick } },
                  y: { ticks: { autoSkip: false } } },
        plugins: { legend: { display: false },
                   title: { display: true, text: spec.title + ' (' + spec.file + ')' } }
      }
    });
    canvas.dataset.rendered = '1';
    markPlotArea(canvas, chart);
  }
  data.charts.forEach(barChart);

  const table = document.getElementById('results');
  const headers = Array.prototype.slice.call(table.tHead.rows[0].cells);
  const tbody = table.tBodies[0];

  function cellText(row, column) {
    const cell = row.cells[column];
    return cell ? cell.textContent.trim() : '';
  }
  // A column is numeric when every run's cell in it is a finite number.
  function numeric(column) {
    return Array.prototype.every.call(tbody.rows, function (row) {
      if (row.dataset.failed) return true;
      const t = cellText(row, column);
      return t !== '' && isFinite(Number(t));
    });
  }
  headers.forEach(function (th, column) {
    if (numeric(column)) {
      th.dataset.numeric = '1';
      Array.prototype.forEach.call(tbody.rows, function (row) {
        if (!row.dataset.failed && row.cells[column]) row.cells[column].classList.add('num');
      });
    }
  });

  function sortBy(column, descending) {
    const isNumber = headers[column].dataset.numeric === '1';
    const rows = Array.prototype.slice.call(tbody.rows);
    const runs = rows.filter(function (r) { return !r.dataset.failed; });
    const failed = rows.filter(function (r) { return r.dataset.failed; });
    runs.sort(function (a, b) {
      const x = cellText(a, column), y = cellText(b, column);
      const order = isNumber ? Number(x) - Number(y) : x.localeCompare(y);
      return descending ? -order : order;
    });
    runs.concat(failed).forEach(function (r) { tbody.appendChild(r); });
    headers.forEach(function (th) { th.removeAttribute('aria-sort'); });
    headers[column].setAttribute('aria-sort', descending ? 'descending' : 'ascending');
    table.dataset.sortedBy = headers[column].textContent;
  }
  headers.forEach(function (th, column) {
    th.addEventListener('click', function () {
      sortBy(column, th.getAttribute('aria-sort') === 'ascending');
    });
  });

  const query = new URLSearchParams(window.location.search);
  if (query.has('sort')) {
    const column = headers.findIndex(function (th) { return th.textContent === query.get('sort'); });
    if (column >= 0) sortBy(column, query.get('order') === 'desc');
  }
  table.dataset.rendered = '1';
  document.body.dataset.rendered = '1';
})();
