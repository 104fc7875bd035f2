// Purpose: injected by tests/report/browser.sh into a copy of a report: once every chart has
// rendered, counts what the browser actually drew in each chart's SVG (line paths and their
// points, band areas, symbols, rules) and appends one line per chart to a pre element, id tf-count.
(function () {
  function count() {
    if (!document.body.hasAttribute('data-rendered')) { setTimeout(count, 50); return; }
    var lines = ['rendered ' + document.body.getAttribute('data-rendered') + ' failed ' +
                 document.body.getAttribute('data-failed')];
    document.querySelectorAll('div.chart').forEach(function (el) {
      var nlines = 0, npoints = 0, nareas = 0, nsymbols = 0;
      el.querySelectorAll('g.mark-line.role-mark path').forEach(function (p) {
        var n = ((p.getAttribute('d') || '').match(/[ML]/g) || []).length;
        if (n > 0) { nlines++; npoints += n; }
      });
      el.querySelectorAll('g.mark-area.role-mark path').forEach(function (p) {
        if ((p.getAttribute('d') || '').length > 0) nareas++;
      });
      nsymbols = el.querySelectorAll('g.mark-symbol.role-mark path').length;
      var nrules = el.querySelectorAll('g.mark-rule.role-mark line').length;
      var svg = el.querySelector('svg');
      var w = svg ? Math.round(svg.getBoundingClientRect().width) : 0;
      var h = svg ? Math.round(svg.getBoundingClientRect().height) : 0;
      // id, expected and drawn: lines, line points, areas, symbols; then the SVG size; then the title;
      // then rules, expected and drawn.
      lines.push(['chart', el.id, el.dataset.lines, nlines, el.dataset.linePoints, npoints, el.dataset.areas, nareas,
                  el.dataset.symbols, nsymbols, w, h, el.dataset.title.replace(/ /g, '_'), el.dataset.rules || 0,
                  nrules].join(' '));
    });
    var pre = document.createElement('pre');
    pre.id = 'tf-count';
    pre.textContent = lines.join('\n') + '\nend\n';
    document.body.appendChild(pre);
  }
  count();
})();
