/* The admin's pool editor (studyapp.admin.pool_editor, studyapp.admin.views_pool).

   For every section form on a study's admin page: show only the fieldsets of the chosen section type (classes
   "only-<type>"; a fieldset of class "not-<type>" is hidden for that type), and while the researcher edits, ask the staff-only count endpoint how many catalogue clips the
   pool matches; its summary, warnings and field errors replace the "matching clips" line. The endpoint gets the
   section's fields as the form would post them, plus touched_pool / touched_options when a structured field of
   that group differs from what the page showed (the server's own rule on save: the raw JSON wins only when they
   are untouched). No inline script: the pages carry a Content-Security-Policy. */
(function () {
  "use strict";

  var DELAY_MS = 250;
  var GROUPS = {pool: "pool_", options: "opt_"};
  var rows = new WeakMap();   // section form row -> {initial: {group: serialized fields}, timer, seq}

  function rowOf(el) {
    var row = el && el.closest ? el.closest(".inline-related") : null;
    if (!row || !row.id || /-empty$/.test(row.id) || !row.querySelector(".pool-count")) {
      return null;
    }
    return row;
  }

  function fieldsOf(row) {
    /* [name without the form prefix, value] of every field of the row, as the browser would post them */
    var prefix = row.id + "-", out = [];
    row.querySelectorAll("input[name], select[name], textarea[name]").forEach(function (el) {
      if (el.name.indexOf(prefix) !== 0 || el.disabled) { return; }
      if ((el.type === "checkbox" || el.type === "radio") && !el.checked) { return; }
      if (el.type === "file" || el.type === "submit" || el.type === "button") { return; }
      var name = el.name.slice(prefix.length);
      if (el.tagName === "SELECT" && el.multiple) {
        Array.prototype.forEach.call(el.selectedOptions, function (o) { out.push([name, o.value]); });
      } else {
        out.push([name, el.value]);
      }
    });
    return out;
  }

  function groupState(pairs, start) {
    return pairs.filter(function (p) { return p[0].indexOf(start) === 0; })
      .map(function (p) { return p[0] + "=" + p[1].trim(); }).sort().join("&");
  }

  function showType(row) {
    var select = row.querySelector("select[name$='-section_type'], input[type='hidden'][name$='-section_type']");
    var type = select ? select.value : "";
    row.querySelectorAll("fieldset[class*='only-']").forEach(function (fs) {
      fs.hidden = !fs.classList.contains("only-" + type);
    });
    row.querySelectorAll("fieldset[class*='not-']").forEach(function (fs) {   // e.g. no clip pool on a page
      fs.hidden = fs.classList.contains("not-" + type) && !fs.querySelector(".errorlist");  // errors stay seen
    });
  }

  function init(row) {
    if (!row || rows.has(row)) { return; }
    var pairs = fieldsOf(row), initial = {};
    Object.keys(GROUPS).forEach(function (g) { initial[g] = groupState(pairs, GROUPS[g]); });
    rows.set(row, {initial: initial, timer: 0, seq: 0});
    showType(row);
  }

  function item(list, text, cls) {
    var li = document.createElement("li");
    li.className = cls;
    li.textContent = text;
    list.appendChild(li);
  }

  function clipCell(c) {
    /* one matching clip as studyapp.data.clip_display draws it: poster thumbnail, title, id */
    var li = document.createElement("li"), cell = document.createElement("span"), thumb;
    cell.className = "clip-cell";
    if (c.thumb_url) {
      thumb = document.createElement("img");
      thumb.src = c.thumb_url;
      thumb.alt = "";
      thumb.width = 85;
      thumb.height = 48;
      thumb.loading = "lazy";
    } else {
      thumb = document.createElement("span");
      thumb.className = "clip-thumb-none";
    }
    thumb.classList.add("clip-thumb");
    var name = document.createElement("span"), title = document.createElement("span");
    var id = document.createElement("code");
    name.className = "clip-name";
    title.className = "clip-title";
    title.textContent = c.title || c.clip_id;
    id.className = "clip-id";
    id.textContent = c.clip_id;
    name.appendChild(title);
    name.appendChild(id);
    cell.appendChild(thumb);
    cell.appendChild(name);
    li.appendChild(cell);
    return li;
  }

  function show(row, status, body) {
    var out = row.querySelector(".pool-count");
    var list = row.querySelector(".pool-warnings");
    var json = row.querySelector(".pool-json");
    out.classList.remove("pool-busy");
    out.textContent = status === 200 ? body.summary : (body.error || "the count could not be fetched");
    out.setAttribute("data-count", body.count === null || body.count === undefined ? "" : String(body.count));
    list.textContent = "";
    (body.errors || []).forEach(function (e) {
      e.messages.forEach(function (m) { item(list, e.label + ": " + m, "pool-error"); });
    });
    (body.warnings || []).forEach(function (w) { item(list, w, "pool-warning"); });
    var samples = row.querySelector(".clip-samples");
    if (samples) {
      samples.textContent = "";
      (status === 200 && body.sample || []).forEach(function (c) { samples.appendChild(clipCell(c)); });
    }
    var norms = row.querySelector(".norms-slot");
    if (norms && status === 200) {
      norms.innerHTML = body.norms_html || "";     // escaped by the server (studyapp.admin.norms)
    }
    if (json && body.pool) {
      json.textContent = "pool " + (body.used && body.used.pool === "fields" ? "(from the fields)" : "(raw JSON)")
        + ": " + JSON.stringify(body.pool);
    }
  }

  function update(row) {
    var state = rows.get(row), pairs = fieldsOf(row), params = new URLSearchParams();
    var out = row.querySelector(".pool-count");
    pairs.forEach(function (p) { params.append(p[0], p[1]); });
    Object.keys(GROUPS).forEach(function (g) {
      if (groupState(pairs, GROUPS[g]) !== state.initial[g]) { params.append("touched_" + g, "on"); }
    });
    var seq = ++state.seq;
    out.classList.add("pool-busy");
    fetch(out.getAttribute("data-url") + "?" + params.toString(),
          {credentials: "same-origin", headers: {"Accept": "application/json"}})
      .then(function (r) { return r.json().then(function (body) { return [r.status, body]; }); })
      .then(function (answer) { if (seq === state.seq) { show(row, answer[0], answer[1]); } })
      .catch(function () { if (seq === state.seq) { show(row, 0, {}); } });
  }

  function edited(event) {
    var row = rowOf(event.target);
    if (!row) { return; }
    init(row);
    if (event.target.name && /-section_type$/.test(event.target.name)) { showType(row); }
    var state = rows.get(row);
    clearTimeout(state.timer);
    state.timer = setTimeout(function () { update(row); }, DELAY_MS);
  }

  document.addEventListener("input", edited);
  document.addEventListener("change", edited);
  document.addEventListener("formset:added", function (event) { init(rowOf(event.target)); });
  function start() {
    document.querySelectorAll(".inline-related .pool-count").forEach(function (el) { init(rowOf(el)); });
  }
  if (document.readyState === "loading") {
    document.addEventListener("DOMContentLoaded", start);
  } else {
    start();
  }
}());
