/* Progressive enhancement of the participant forms. Without JS every form still works (the server checks all).
   Clip page:
   - the address bar shows the page's own URL, also when the page came as the answer to the previous clip's POST;
   - answers are enabled once the clip has played through (when the section requires it);
   - replay button; response time measured from page display to submit (hidden field "rt", ms);
   - the next clip is preloaded once this one can play; a double submit is blocked.
   Every form with data-keys (clip, demographics, feedback pages): keyboard answering
   - number keys 1-9 choose option 1-9 of the question that has focus, or else of the first unanswered question
     (a checkbox is toggled); nothing happens while the answers are not enabled yet;
   - Enter continues (submits) once the answers are enabled; on a button, link, text box or the video Enter keeps
     its usual meaning.
   The sentences shown come from data attributes the server wrote in the study's language. */
(function () {
  "use strict";
  // A page restored from the back/forward cache may be stale: ask the server where the participant is.
  window.addEventListener("pageshow", function (e) { if (e.persisted) { window.location.reload(); } });
  var t0 = performance.now();
  var form = document.getElementById("answer-form");
  if (!form) { return; }
  // A clip page that answers the previous clip's POST is shown under that POST's URL: give the history entry the
  // page's own URL (the form's action), so a reload or a bookmark asks the server for this page with a GET instead
  // of resending the previous answer (the server would ignore it, but the browser would ask first).
  if (form.getAttribute("action") && window.history && window.history.replaceState) {
    window.history.replaceState(window.history.state, "", form.getAttribute("action"));
  }
  var submit = document.getElementById("next");
  var live = liveRegion();
  var video = document.getElementById("clip");
  if (video) { setUpPlayer(video); }
  if (form.dataset.keys) { setUpKeys(); }
  setUpSubmit();

  function liveRegion() {
    var el = document.createElement("p");
    el.className = "sr-only";
    el.setAttribute("aria-live", "polite");
    document.body.appendChild(el);
    return el;
  }

  function setUpPlayer(video) {
    var fieldsets = form.querySelectorAll("fieldset");
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
      note.textContent = note.dataset.ready;
    }
    if (requirePlay && !form.querySelector(".error")) {
      setEnabled(false);
      note.textContent = note.dataset.wait;
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
    video.addEventListener("error", function () { setEnabled(true); note.textContent = note.dataset.failed; },
                           true);
    var p = video.play();
    if (p && p.catch) { p.catch(function () { note.textContent = note.dataset.pressPlay; }); }
    video.addEventListener("canplaythrough", preloadNext);
    setTimeout(preloadNext, 4000);
  }

  function preloadNext() {
    var next = document.getElementById("next-clip");
    if (!next || next.dataset.done) { return; }
    next.dataset.done = "1";
    var v = document.createElement("video");
    v.preload = "auto"; v.muted = true; v.hidden = true;
    v.src = (next.dataset.webm && v.canPlayType("video/webm")) ? next.dataset.webm : next.dataset.mp4;
    document.body.appendChild(v);
  }

  function choiceQuestions() {
    return Array.prototype.filter.call(form.querySelectorAll("fieldset.question"), function (fs) {
      return fs.querySelector("input[type=radio], input[type=checkbox]");
    });
  }

  function targetQuestion(active) {
    var questions = choiceQuestions();
    var i;
    for (i = 0; i < questions.length; i++) { if (questions[i].contains(active)) { return questions[i]; } }
    for (i = 0; i < questions.length; i++) { if (!questions[i].querySelector("input:checked")) { return questions[i]; } }
    return null;
  }

  function isTyping(el) {
    if (!el) { return false; }
    if (el.tagName === "TEXTAREA" || el.tagName === "SELECT" || el.isContentEditable) { return true; }
    return el.tagName === "INPUT" && !/^(radio|checkbox)$/.test(el.type);
  }

  // Digit key -> option: on a numbered scale whose values are all single digits (0-4 Likert, 1-5 naturalness) the
  // option showing that number; otherwise the n-th option (1 = first).
  function optionForDigit(inputs, n) {
    var numbered = Array.prototype.every.call(inputs, function (i) { return /^[0-9]$/.test(i.value); });
    if (numbered) {
      return Array.prototype.find.call(inputs, function (i) { return i.value === String(n); });
    }
    return n >= 1 ? inputs[n - 1] : undefined;
  }

  function choose(fs, n, active) {
    var inputs = fs.querySelectorAll("input[type=radio], input[type=checkbox]");
    var input = optionForDigit(inputs, n);
    if (!input || input.disabled || fs.disabled) { return false; }
    input.checked = input.type === "checkbox" ? !input.checked : true;
    input.dispatchEvent(new Event("change", { bubbles: true }));
    if (fs.contains(active)) { input.focus(); }
    var legend = fs.querySelector("legend");
    var label = input.closest("label");
    live.textContent = (legend ? legend.textContent.trim() + " " : "") + (label ? label.textContent.trim() : "");
    return true;
  }

  function setUpKeys() {
    document.addEventListener("keydown", function (e) {
      if (e.altKey || e.ctrlKey || e.metaKey || e.defaultPrevented) { return; }
      var active = document.activeElement;
      if (isTyping(active)) { return; }
      if (/^[0-9]$/.test(e.key)) {
        var fs = targetQuestion(active);
        if (fs && choose(fs, Number(e.key), active)) { e.preventDefault(); }
        return;
      }
      if (e.key !== "Enter" || !active) { return; }
      if (/^(BUTTON|A|VIDEO|SUMMARY)$/.test(active.tagName)) { return; }   // their own meaning of Enter
      e.preventDefault();
      if (submit.disabled) { return; }                                   // answers not enabled yet
      if (form.requestSubmit) { form.requestSubmit(submit); } else { submit.click(); }
    });
  }

  function setUpSubmit() {
    var sent = false;
    form.addEventListener("submit", function (e) {
      if (sent) { e.preventDefault(); return; }
      sent = true;
      var rt = document.getElementById("rt");
      if (rt) { rt.value = String(Math.round(performance.now() - t0)); }
      submit.disabled = false;
      setTimeout(function () { submit.disabled = true; }, 0);
    });
  }
})();
