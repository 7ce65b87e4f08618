/* Device check of the consent page: before the study starts, says so when the viewport is too small for the clip
   player (the study's minimum), the browser can play none of the clip formats, or the study does not admit this
   kind of device (phone, tablet), and keeps the start button disabled meanwhile (checked again when the window is
   resized or the device turned). The viewport and the kind go with the consent form (hidden fields), and the
   server checks them again and records them (studyapp.participant.device_check). The limits and sentences come from data
   attributes of #device-check that the server wrote in the study's language; without JS the server alone checks
   the kind, from the User-Agent. */
(function () {
  "use strict";
  var box = document.getElementById("device-check");
  if (!box) { return; }
  var start = document.getElementById("start-study");
  var minW = Number(box.dataset.minWidth), minH = Number(box.dataset.minHeight);
  var probe = document.createElement("video");
  var playable = (box.dataset.types || "").split("|").some(function (t) { return t && probe.canPlayType(t) !== ""; });

  var admits = (box.dataset.admits || "desktop|tablet|phone").split("|");

  // phone or tablet: a touch screen without a fine pointer, by its shorter side (iPadOS says "Macintosh" but has
  // touch points); everything else is a desktop
  function deviceKind() {
    var coarse = window.matchMedia && window.matchMedia("(pointer: coarse)").matches &&
      !window.matchMedia("(any-pointer: fine)").matches;
    var ipad = /Macintosh/.test(navigator.userAgent) && navigator.maxTouchPoints > 1;
    if (!coarse && !ipad) { return "desktop"; }
    return Math.min(window.screen.width, window.screen.height) < 600 ? "phone" : "tablet";
  }

  function record(kind) {
    var values = {width: String(window.innerWidth), height: String(window.innerHeight), kind: kind};
    document.querySelectorAll("input[data-device]").forEach(function (input) {
      input.value = values[input.dataset.device];
    });
  }

  function problems() {
    var out = [];
    var kind = deviceKind();
    record(kind);
    if (admits.indexOf(kind) < 0) { out.push(box.dataset[kind] || box.dataset.phone); }
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
