// settle report: sortable, filterable, paged tables. The page reads without this script;
// it only adds controls. Hooks for tests: see `#selftest` in src/html/mod.rs.
(function () {
  'use strict';
  var errors = [];
  window.addEventListener('error', function (e) { errors.push(String(e.message)); });
  document.documentElement.classList.add('js');

  var PAGE = 100;
  var PAGE_SIZES = [50, 100, 500, 1000];
  var FILTER_MIN_ROWS = 10;
  var LIST_MAX_VALUES = 12;
  var ENTITIES = { amp: '&', lt: '<', gt: '>', quot: '"', '#39': "'" };
  var collator = new Intl.Collator(undefined, { numeric: true, sensitivity: 'base' });
  var grids = [];

  function el(tag, attrs, text) {
    var e = document.createElement(tag);
    for (var k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function unescapeHtml(s) {
    return s.indexOf('&') < 0 ? s : s.replace(/&(amp|lt|gt|quot|#39);/g, function (m, e) {
      return ENTITIES[e];
    });
  }

  // Rows already in the DOM: texts, and the sort keys some number cells carry in data-v.
  function domRows(tbody) {
    return Array.prototype.map.call(tbody.rows, function (tr) {
      var t = [], k = null;
      for (var j = 0; j < tr.cells.length; j++) {
        var c = tr.cells[j];
        t.push(c.textContent);
        if (c.hasAttribute('data-v')) (k = k || {})[j] = c.getAttribute('data-v');
      }
      return { tr: tr, t: t, k: k };
    });
  }

  // Rows of a large table from its <noscript> text, which the renderer writes as
  // `<tr><td>text<td>text</tr>` lines of escaped text without attributes.
  function textRows(markup) {
    var body = markup.slice(markup.indexOf('<tbody>') + 7, markup.lastIndexOf('</tbody>'));
    var parts = body.split('<tr>'), rows = [];
    for (var i = 1; i < parts.length; i++) {
      var p = parts[i];
      var cells = p.slice(0, p.lastIndexOf('</tr>')).split('<td>');
      cells.shift();
      for (var j = 0; j < cells.length; j++) cells[j] = unescapeHtml(cells[j]);
      rows.push({ tr: null, t: cells, k: null });
    }
    return rows;
  }

  function Grid(box) {
    var g = this, ns = box.querySelector('noscript');
    g.lazy = !!ns;
    if (ns) {
      var markup = ns.textContent, holder = el('div');
      holder.innerHTML = markup.slice(0, markup.indexOf('<tbody>')) + '<tbody></tbody></table></div>';
      g.rows = textRows(markup);
      ns.replaceWith(holder.firstElementChild);
    }
    g.box = box;
    g.id = box.parentNode.id;
    g.table = box.querySelector('table');
    g.tbody = g.table.tBodies[0];
    if (!ns) g.rows = domRows(g.tbody);
    g.ths = Array.prototype.slice.call(g.table.tHead.rows[0].cells);
    g.names = g.ths.map(function (th) { return th.textContent; });
    g.num = g.ths.map(function (th) { return th.getAttribute('data-type') === 'num'; });
    g.keys = [];
    g.col = -1;
    g.dir = 1;
    g.sorted = g.rows.map(function (r, i) { return i; });
    g.view = g.sorted;
    g.page = 0;
    g.size = PAGE;
    g.query = '';
    g.colTests = [];
    g.ths.forEach(function (th, j) {
      var b = el('button', { type: 'button', 'class': 'sort', title: 'Sort' }, g.names[j]);
      b.addEventListener('click', function () { g.sortBy(j); });
      th.replaceChildren(b);
    });
    if (g.rows.length > FILTER_MIN_ROWS) g.controls();
    g.render();
  }

  // A cell as a number: `inf` (not settled) is Infinity; empty is NaN.
  function parseNum(s) {
    if (s === undefined || s.trim() === '') return NaN;
    var x = Number(s), m;
    if (x === x) return x;
    m = /^\s*([+-]?)inf(inity)?\s*$/i.exec(s);
    return m ? (m[1] === '-' ? -Infinity : Infinity) : NaN;
  }

  // Sort keys of column j: numbers or texts.
  Grid.prototype.keysOf = function (j) {
    if (this.keys[j]) return this.keys[j];
    var rows = this.rows, n = rows.length, ks;
    if (this.num[j]) {
      ks = new Float64Array(n);
      for (var i = 0; i < n; i++) {
        var r = rows[i];
        ks[i] = parseNum(r.k && r.k[j] !== undefined ? r.k[j] : r.t[j]);
      }
    } else {
      ks = rows.map(function (r) { return r.t[j] || ''; });
    }
    return (this.keys[j] = ks);
  };

  // Numbers ascending (dir 1) or descending (dir -1); non-finite (inf, NaN) last either way.
  function cmpNum(x, y, dir) {
    var a = !isFinite(x), b = !isFinite(y);
    if (a || b) return a - b;
    return (x - y) * dir;
  }

  // Texts in the reader's collation; empty last either way.
  function cmpText(x, y, dir) {
    if (!x || !y) return !x - !y;
    return collator.compare(x, y) * dir;
  }

  Grid.prototype.sortBy = function (j) {
    this.dir = this.col === j ? -this.dir : 1;
    this.col = j;
    var ks = this.keysOf(j), dir = this.dir, cmp = this.num[j] ? cmpNum : cmpText;
    this.sorted = this.rows.map(function (r, i) { return i; });
    this.sorted.sort(function (a, b) { return cmp(ks[a], ks[b], dir) || a - b; });
    var g = this;
    this.ths.forEach(function (th, i) {
      if (i === j) th.setAttribute('aria-sort', g.dir > 0 ? 'ascending' : 'descending');
      else th.removeAttribute('aria-sort');
    });
    this.filter();
  };

  // A column filter: `>x`, `>=x`, `<x`, `<=x`, `=x`, `a..b` on a number column; otherwise a
  // case-insensitive substring.
  function columnTest(text, numeric) {
    var q = text.trim(), m;
    if (numeric && (m = /^(<=|>=|<|>|=)\s*(\S+)$/.exec(q)) && !isNaN(Number(m[2]))) {
      var v = Number(m[2]), op = m[1];
      return function (x) {
        return op === '<' ? x < v : op === '<=' ? x <= v : op === '>' ? x > v : op === '>=' ? x >= v : x === v;
      };
    }
    if (numeric && (m = /^(\S+)\s*\.\.\s*(\S+)$/.exec(q)) && !isNaN(Number(m[1])) && !isNaN(Number(m[2]))) {
      var lo = Number(m[1]), hi = Number(m[2]);
      return function (x) { return x >= lo && x <= hi; };
    }
    q = q.toLowerCase();
    return function (x, s) { return s.toLowerCase().indexOf(q) >= 0; };
  }

  Grid.prototype.setColumnFilter = function (j, text, exact) {
    this.colTests = this.colTests.filter(function (f) { return f.j !== j; });
    if (text !== '') {
      this.colTests.push({
        j: j,
        test: exact ? function (x, s) { return s === text; } : columnTest(text, this.num[j]),
        keys: this.num[j] ? this.keysOf(j) : null
      });
    }
    this.filter();
  };

  Grid.prototype.filter = function () {
    var q = this.query, tests = this.colTests, rows = this.rows;
    if (!q && !tests.length) {
      this.view = this.sorted;
    } else {
      this.view = this.sorted.filter(function (i) {
        var r = rows[i];
        if (q && (r.h || (r.h = r.t.join('\t').toLowerCase())).indexOf(q) < 0) return false;
        for (var f = 0; f < tests.length; f++) {
          var t = tests[f], s = r.t[t.j] || '';
          if (!t.test(t.keys ? t.keys[i] : s, s)) return false;
        }
        return true;
      });
    }
    this.page = 0;
    this.render();
  };

  Grid.prototype.controls = function () {
    var g = this, bar = el('div', { 'class': 'controls' });
    g.search = el('input', { type: 'search', placeholder: 'Filter all columns', 'aria-label': 'Filter all columns' });
    g.search.addEventListener('input', function () { g.query = g.search.value.trim().toLowerCase(); g.filter(); });
    g.info = el('span', { 'class': 'count' });
    g.prev = el('button', { type: 'button' }, '\u2039 Prev');
    g.next = el('button', { type: 'button' }, 'Next \u203a');
    g.prev.addEventListener('click', function () { g.page--; g.render(); });
    g.next.addEventListener('click', function () { g.page++; g.render(); });
    var size = el('select', { 'aria-label': 'Rows per page' });
    PAGE_SIZES.forEach(function (n) {
      var o = el('option', { value: String(n) }, n + ' rows');
      o.selected = n === PAGE;
      size.appendChild(o);
    });
    size.addEventListener('change', function () { g.size = Number(size.value); g.page = 0; g.render(); });
    bar.append(g.search, g.info, g.prev, g.next, size);
    g.box.insertBefore(bar, g.box.firstChild);
    var row = el('tr', { 'class': 'filters' });
    g.colInputs = g.ths.map(function (th, j) {
      var cell = el('th'), input = g.listFor(j);
      var exact = input.tagName === 'SELECT';
      input.setAttribute('aria-label', 'Filter ' + g.names[j]);
      input.addEventListener(exact ? 'change' : 'input', function () { g.setColumnFilter(j, input.value, exact); });
      cell.appendChild(input);
      row.appendChild(cell);
      return input;
    });
    g.table.tHead.appendChild(row);
  };

  // A list of values for a text column with few distinct values, else a text box.
  Grid.prototype.listFor = function (j) {
    if (!this.num[j]) {
      var seen = new Set();
      for (var i = 0; i < this.rows.length && seen.size <= LIST_MAX_VALUES; i++) {
        if (this.rows[i].t[j]) seen.add(this.rows[i].t[j]);
      }
      if (seen.size <= LIST_MAX_VALUES && seen.size < this.rows.length) {
        var s = el('select');
        s.appendChild(el('option', { value: '' }, 'all'));
        Array.from(seen).sort(collator.compare).forEach(function (v) { s.appendChild(el('option', { value: v }, v)); });
        return s;
      }
    }
    return el('input', { type: 'text', placeholder: this.num[j] ? '>x, a..b' : 'filter' });
  };

  Grid.prototype.rowElement = function (i) {
    var r = this.rows[i];
    if (!r.tr) {
      r.tr = el('tr');
      for (var j = 0; j < r.t.length; j++) r.tr.appendChild(el('td', this.num[j] ? { 'class': 'n' } : {}, r.t[j]));
    }
    return r.tr;
  };

  Grid.prototype.render = function (all) {
    var total = this.view.length, size = all ? Math.max(total, 1) : this.size;
    var pages = Math.max(1, Math.ceil(total / size));
    var page = all ? 0 : (this.page = Math.min(Math.max(this.page, 0), pages - 1));
    var from = page * size, to = Math.min(total, from + size), frag = document.createDocumentFragment();
    for (var i = from; i < to; i++) frag.appendChild(this.rowElement(this.view[i]));
    this.tbody.replaceChildren(frag);
    if (this.info) {
      this.info.textContent = (total ? 'rows ' + (from + 1) + '\u2013' + to + ' of ' + total : 'no rows') +
        (total < this.rows.length ? ' (filtered from ' + this.rows.length + ')' : '');
      this.prev.disabled = page === 0;
      this.next.disabled = page >= pages - 1;
    }
  };

  var t0 = performance.now();
  document.querySelectorAll('div.grid').forEach(function (box) { grids.push(new Grid(box)); });
  var initMs = performance.now() - t0;

  // Printing shows every row that passes the filters, and the input files.
  var closed = [];
  window.addEventListener('beforeprint', function () {
    grids.forEach(function (g) { g.render(true); });
    closed = Array.prototype.filter.call(document.querySelectorAll('details'), function (d) { return !d.open; });
    closed.forEach(function (d) { d.open = true; });
  });
  window.addEventListener('afterprint', function () {
    grids.forEach(function (g) { g.render(); });
    closed.forEach(function (d) { d.open = false; });
  });

  function rect(e) {
    if (!e) return null;
    var b = e.getBoundingClientRect();
    return { x: b.left + window.scrollX, y: b.top + window.scrollY, w: b.width, h: b.height };
  }

  function selftest() {
    var p = {};
    location.hash.slice(1).split('&').forEach(function (kv) {
      var i = kv.indexOf('=');
      if (kv) p[i < 0 ? kv : kv.slice(0, i)] = i < 0 ? '' : decodeURIComponent(kv.slice(i + 1));
    });
    if (!('selftest' in p)) return;
    var id = p.grid || 'runs', g = grids.filter(function (x) { return x.id === id; })[0];
    var res = { grids: grids.length, init_ms: initMs, errors: errors };
    res.images = Array.prototype.map.call(document.images, function (i) { return i.naturalWidth; });
    res.sections = Array.prototype.map.call(document.querySelectorAll('section.part'), function (s) {
      var drawn = Array.prototype.filter.call(s.querySelectorAll('figure .img > svg'), function (v) {
        var b = v.getBoundingClientRect();
        return b.width > 0 && b.height > 0;
      });
      return { id: s.id, title: s.querySelector('h2').textContent, tables: s.querySelectorAll('div.grid').length,
        figures: s.querySelectorAll('figure').length, svgs: drawn.length };
    });
    if (g) {
      res.rows = g.rows.length;
      res.columns = g.names;
      res.lazy = g.lazy;
      res.rects = { table: rect(g.table.closest('.scroll') || g.table), figure: rect(document.querySelector('figure .img > *')) };
      var shown = function (j) {
        return Array.prototype.map.call(g.tbody.rows, function (tr) { return tr.cells[j].textContent; });
      };
      if (p.col !== undefined) {
        var j = g.names.indexOf(p.col), button = j < 0 ? null : g.ths[j].querySelector('button');
        res.col = j;
        if (button) {
          var t = performance.now();
          button.click();
          res.sort_ms = performance.now() - t;
          res.asc = shown(j);
          res.asc_aria = g.ths[j].getAttribute('aria-sort');
          button.click();
          res.desc = shown(j);
          res.desc_aria = g.ths[j].getAttribute('aria-sort');
        }
      }
      var typed = function (input, value) {
        input.value = value;
        input.dispatchEvent(new Event(input.tagName === 'SELECT' ? 'change' : 'input'));
      };
      var t1 = performance.now();
      if (p.filter !== undefined && g.search) typed(g.search, p.filter);
      if (p.colfilter !== undefined && g.colInputs) {
        var c = p.colfilter.indexOf(':'), k = g.names.indexOf(p.colfilter.slice(0, c));
        if (k >= 0) typed(g.colInputs[k], p.colfilter.slice(c + 1));
      }
      res.filter_ms = performance.now() - t1;
      res.matched = g.view.length;
      res.shown = g.tbody.rows.length;
    }
    document.body.appendChild(el('pre', { id: 'selftest-result' }, JSON.stringify(res)));
  }
  selftest();
})();
