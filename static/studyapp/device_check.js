/* Device check of the consent page: before the study starts, says so when the viewport is too small for the clip
   player or the browser can play none of the clip formats, and keeps the start button disabled meanwhile (checked
   again when the window is resized or the device turned). The limits and sentences come from data attributes of
   #device-check that the server wrote in the study's language; without JS nothing is checked. */
(function () {
  "use strict";
  var box = document.getElementById("device-check");
  if (!box) { return; }
  var start = document.getElementById("start-study");
  var minW = Number(box.dataset.minWidth), minH = Number(box.dataset.minHeight);
  var probe = document.createElement("video");
  var playable = (box.dataset.types || "").split("|").some(function (t) { return t && probe.canPlayType(t) !== ""; });

  function problems() {
    var out = [];
    var w = window.innerWidth, h = window.innerHeight;
    if (w < minW || h < minH) {
      out.push(box.dataset.small.replace("{min}", minW + " × " + minH).replace("{size}", w + " × " + h));
    }
    if (!playable) { out.push(box.dataset.format); }
    return out;
  }

  function check() {
    var found = problems();
    box.textContent = "";
    found.forEach(function (text) {
      var p = document.createElement("p");
      p.textContent = text;
      box.appendChild(p);
    });
    box.hidden = found.length === 0;
    box.dataset.problems = String(found.length);
    if (start) { start.disabled = found.length > 0; }
  }

  check();
  window.addEventListener("resize", check);
  window.addEventListener("orientationchange", check);
})();
