/* Progressive enhancement of the clip page. Without JS the form still works (the server checks everything).
   - answers are enabled once the clip has played through (when the section requires it);
   - replay button; response time measured from page display to submit (hidden field "rt", ms);
   - the next clip is preloaded once this one can play; a double submit is blocked. */
(function () {
  "use strict";
  // A page restored from the back/forward cache may be stale: ask the server where the participant is.
  window.addEventListener("pageshow", function (e) { if (e.persisted) { window.location.reload(); } });
  var t0 = performance.now();
  var video = document.getElementById("clip");
  var form = document.getElementById("answer-form");
  if (!video || !form) { return; }
  var fieldsets = form.querySelectorAll("fieldset");
  var submit = document.getElementById("next");
  var note = document.getElementById("play-note");
  var replay = document.getElementById("replay");
  var requirePlay = video.dataset.requirePlay === "1";
  var played = false;

  function setEnabled(on) {
    fieldsets.forEach(function (fs) { fs.disabled = !on; });
    submit.disabled = !on;
  }
  function markPlayed() {
    if (played) { return; }
    played = true;
    setEnabled(true);
    note.textContent = "You can answer now. Replay the clip as often as you like.";
  }
  if (requirePlay && !form.querySelector(".error")) {
    setEnabled(false);
    note.textContent = "The answers are enabled once the clip has played.";
  }
  replay.hidden = false;
  replay.addEventListener("click", function () { video.currentTime = 0; video.play(); });
  video.addEventListener("ended", markPlayed);
  var last = 0;
  video.addEventListener("timeupdate", function () {
    // A looping clip never fires "ended": count a wrap-around (time jumping back) as one full play.
    if (video.loop && video.currentTime + 0.25 < last && last > 0.5 * (video.duration || 0)) { markPlayed(); }
    last = video.currentTime;
  });
  video.addEventListener("error", function () { setEnabled(true); note.textContent = "The clip could not be played."; },
                         true);
  var p = video.play();
  if (p && p.catch) { p.catch(function () { note.textContent = "Press play to start the clip."; }); }

  function preloadNext() {
    var next = document.getElementById("next-clip");
    if (!next || next.dataset.done) { return; }
    next.dataset.done = "1";
    var v = document.createElement("video");
    v.preload = "auto"; v.muted = true; v.hidden = true;
    var src = (next.dataset.webm && v.canPlayType("video/webm")) ? next.dataset.webm : next.dataset.mp4;
    v.src = src;
    document.body.appendChild(v);
  }
  video.addEventListener("canplaythrough", preloadNext);
  setTimeout(preloadNext, 4000);

  var sent = false;
  form.addEventListener("submit", function (e) {
    if (sent) { e.preventDefault(); return; }
    sent = true;
    document.getElementById("rt").value = String(Math.round(performance.now() - t0));
    submit.disabled = false;
    setTimeout(function () { submit.disabled = true; }, 0);
  });
})();
