/* Progressive enhancement of the participant forms. Without JS every form still works (the server checks all).
   Clip page:
   - the address bar shows the page's own URL, also when the page came as the answer to the previous clip's POST;
   - answers are enabled once the clip has played through (when the section requires it);
   - the player's controls, replay limit and seek blocking, and the viewing record sent with the answer
     (setUpPlayer); response time measured from page display to submit (hidden field "rt", ms);
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
  var fillViewing = video ? setUpPlayer(video) : null;
  if (form.dataset.keys) { setUpKeys(); }
  setUpSubmit();

  function liveRegion() {
    var el = document.createElement("p");
    el.className = "sr-only";
    el.setAttribute("aria-live", "polite");
    document.body.appendChild(el);
    return el;
  }

  // The clip player (the section's options, data-controls / data-max-replays on the video):
  // - "replay-only": a play/pause and a Replay button, no seek bar, no speed menu; "none": only Replay, once the clip
  //   ended; "full": the browser's own controls. Outside "full" every seek is undone (the seek bar of picture-in-
  //   picture, the keyboard, media keys, a script) and the speed is kept at 1.
  // - data-max-replays (blank: unlimited) limits the plays after the first.
  // - the viewing record goes with the answer as hidden fields view_<field> (protocol.vocabulary.VIEWING_FIELDS; times
  //   in ms from the page's display): first playing frame, first end, plays, pauses, seek attempts, stalls (playback
  //   waiting for data after the first frame) and their total time, start-up time (first play request to first
  //   frame), how often and how long the page was hidden while the clip played; view_script=1 says this ran.
  // - every play from the start and the first end are reported to the server while the page is open
  //   (data-playback-url); a reload gets them back (data-plays-before, data-ended-before), so it neither resets
  //   the replay limit nor forgets that the clip was watched to its end.
  // - a clip already playing when this script attaches counts as played; a pause the browser makes because the
  //   page was hidden is hidden time, not a pause, and the clip goes on when the page is shown again.
  function setUpPlayer(video) {
    var fieldsets = form.querySelectorAll("fieldset");
    var note = document.getElementById("play-note");
    var replay = document.getElementById("replay");
    var playPause = document.getElementById("play-pause");
    var requirePlay = video.dataset.requirePlay === "1";
    var controls = video.dataset.controls || "full";
    var canSeek = controls === "full";
    var maxReplays = video.dataset.maxReplays ? Number(video.dataset.maxReplays) : Infinity;
    var priorPlays = Number(video.dataset.playsBefore || 0);     // plays during earlier displays of this page
    var endedBefore = video.dataset.endedBefore === "1";
    var playbackUrl = video.dataset.playbackUrl || "";
    var rec = { first_play_ms: null, ended_ms: null, plays: 0, pauses: 0, seeks: 0, stalls: 0, stall_ms: 0,
                hidden: 0, startup_ms: null, hidden_ms: 0 };
    var scriptField = form.querySelector("input[data-viewing-script]");
    if (scriptField) { scriptField.value = "1"; }
    var played = false;        // reached its end once: answers enabled
    var atEnd = false;         // ended and not started again yet
    var ownSeeks = 0;          // seeks this script makes (replay, undoing a blocked seek), not counted as attempts
    var ownPause = false;      // a pause this script makes (replays used up), not counted as the participant's
    var safeTime = 0;          // how far the clip got by playing: where a blocked seek returns to
    var stallStart = null;
    var blocked = false;       // the browser did not let the clip start by itself
    var playRequested = null;  // when the first play was asked for (start-up time runs from here)
    var hiddenSince = null;    // the page is hidden while the clip plays (or was stopped by the hiding)
    var pausedByHiding = false;
    var endReported = endedBefore;
    var answered = false;      // the form was sent: its record carries the counts, no "leave" report
    function now() { return Math.round(performance.now() - t0); }
    function playsSoFar() { return priorPlays + rec.plays; }
    function replaysLeft() { return playsSoFar() === 0 ? Infinity : maxReplays - (playsSoFar() - 1); }
    function reportData(event) {
      var data = new FormData();
      var csrf = form.querySelector("input[name=csrfmiddlewaretoken]");
      if (csrf) { data.append("csrfmiddlewaretoken", csrf.value); }
      data.append("event", event);
      return data;
    }
    function report(event) {
      if (!playbackUrl || !window.fetch || !window.FormData) { return; }
      fetch(playbackUrl, { method: "POST", body: reportData(event), credentials: "same-origin", keepalive: true })
        .catch(function () { /* the answer's own record still goes with the form */ });
    }
    // Left without an answer (a reload, the back button): this display's counts go to the server, which adds
    // them to the answer's record (studyapp.participant.viewing.CARRIED_FIELDS).
    window.addEventListener("pagehide", function () {
      if (answered || !playbackUrl || !navigator.sendBeacon || !window.FormData) { return; }
      closeTimers();
      var data = reportData("leave");
      ["pauses", "seeks", "stalls", "stall_ms", "hidden", "hidden_ms"].forEach(function (key) {
        data.append("view_" + key, String(rec[key]));
      });
      navigator.sendBeacon(playbackUrl, data);
    });
    function closeTimers() {
      if (stallStart !== null) { rec.stall_ms += now() - stallStart; stallStart = null; }
      if (hiddenSince !== null) { rec.hidden_ms += now() - hiddenSince; hiddenSince = null; }
    }
    function countPlay() { rec.plays += 1; report("play"); }
    function setEnabled(on) {
      fieldsets.forEach(function (fs) { fs.disabled = !on; });
      submit.disabled = !on;
    }
    function say(text) { if (text) { note.textContent = text; } }
    function markPlayed() {
      if (rec.ended_ms === null) { rec.ended_ms = now(); }
      if (!endReported) { endReported = true; report("ended"); }
      if (played) { return; }
      played = true;
      setEnabled(true);
      say(note.dataset.ready + (note.dataset.replaysLeft ? " " + note.dataset.replaysLeft : ""));
    }
    function updateButtons() {
      var left = replaysLeft();
      replay.hidden = controls === "none" ? !((atEnd && left > 0) || (rec.plays === 0 && blocked)) : maxReplays === 0;
      replay.disabled = left <= 0;
      if (played && left <= 0 && maxReplays > 0) { say(note.dataset.noReplays); }
      if (playPause) {
        playPause.hidden = false;
        playPause.textContent = video.paused || video.ended ? playPause.dataset.play : playPause.dataset.pause;
      }
    }
    function seekTo(t) { ownSeeks += 1; video.currentTime = t; }
    function startOver() {          // a replay: one more play from the start, if any is left
      if (replaysLeft() <= 0) { return false; }
      countPlay();
      atEnd = false;
      safeTime = 0;
      seekTo(0);
      return true;
    }
    function stopHere() { ownPause = true; video.pause(); }
    // Watched to its end before a reload, or every play used up before it (a reload mid-play with no replay left
    // must not leave the participant unable to answer; the record then shows no end): the answers are enabled.
    if (endedBefore || (priorPlays > 0 && replaysLeft() <= 0)) {
      played = true;
      atEnd = video.paused;
      if (replaysLeft() <= 0 && maxReplays > 0) { say(note.dataset.noReplays); }
    } else if (requirePlay && !form.querySelector(".error")) {
      setEnabled(false);
      say(note.dataset.wait);
    }
    replay.addEventListener("click", function () {
      if (playsSoFar() === 0) { video.play(); return; }   // autoplay was blocked: this is the first play
      if (startOver()) { video.play(); }
      updateButtons();
    });
    if (playPause) {
      playPause.addEventListener("click", function () {
        if (atEnd) { if (startOver()) { video.play(); } } else if (video.paused) { video.play(); } else { video.pause(); }
        updateButtons();
      });
    }
    function onPlaying() {
      if (rec.first_play_ms === null) {
        rec.first_play_ms = now();
        if (playRequested !== null) { rec.startup_ms = rec.first_play_ms - playRequested; }
        if (rec.plays === 0) { countPlay(); }
      }
      if (stallStart !== null) { rec.stall_ms += now() - stallStart; stallStart = null; }
      updateButtons();
    }
    video.addEventListener("playing", onPlaying);
    video.addEventListener("play", function () {
      if (playRequested === null) { playRequested = now(); }
      // The browser's own play button on an ended clip (full controls) starts it over: a replay.
      if (atEnd) {
        if (!startOver()) { stopHere(); }
      } else if (rec.plays === 0 && replaysLeft() <= 0) {
        stopHere();                    // every play was used during earlier displays of the page
      }
      updateButtons();
    });
    video.addEventListener("pause", function () {
      if (document.hidden) {
        pausedByHiding = !ownPause && !video.ended;      // the browser's doing: hidden time, not a pause
      } else if (!ownPause && !video.ended && !atEnd) {
        rec.pauses += 1;
      }
      ownPause = false;
      updateButtons();
    });
    video.addEventListener("ended", function () { atEnd = true; markPlayed(); updateButtons(); });
    video.addEventListener("waiting", function () {
      // buffering before the first frame is start-up time (startup_ms), not a stall
      if (rec.first_play_ms === null || document.hidden) { return; }
      if (!video.seeking && !video.paused && stallStart === null) { rec.stalls += 1; stallStart = now(); }
    });
    video.addEventListener("seeking", function () {
      if (ownSeeks > 0) { ownSeeks -= 1; return; }
      var t = video.currentTime;
      if (video.loop && t < 0.5 && safeTime > (video.duration || 0) - 0.75) { return; }   // a loop starting over
      if (atEnd && t < 0.1) { return; }            // the browser restarts an ended clip on play
      rec.seeks += 1;
      if (!canSeek && Math.abs(t - safeTime) > 0.05) {
        seekTo(safeTime);
        say(note.dataset.noSeek);
      }
    });
    var last = 0;
    video.addEventListener("timeupdate", function () {
      var t = video.currentTime;
      // A looping clip never fires "ended": count a wrap-around (time jumping back) as one full play, and as a
      // replay once it has played through.
      if (video.loop && t + 0.25 < last && last > 0.5 * (video.duration || 0)) {
        markPlayed();
        safeTime = 0;
        if (replaysLeft() <= 0) { stopHere(); atEnd = true; } else { countPlay(); }
        updateButtons();
      }
      if (!video.seeking && t >= safeTime && t - safeTime < 1.5) { safeTime = t; }
      last = t;
    });
    video.addEventListener("ratechange", function () {
      if (!canSeek && video.playbackRate !== 1) { video.playbackRate = 1; }
    });
    if (!canSeek) {
      // Arrow keys, Home/End, j/l and the like seek a focused video in some browsers.
      video.addEventListener("keydown", function (e) {
        if (/^(Arrow(Left|Right|Up|Down)|Home|End|PageUp|PageDown|j|l|,|\.)$/.test(e.key)) {
          e.preventDefault();
          e.stopPropagation();
          rec.seeks += 1;
          say(note.dataset.noSeek);
        }
      });
      if (navigator.mediaSession && navigator.mediaSession.setActionHandler) {
        ["seekto", "seekbackward", "seekforward", "previoustrack", "nexttrack"].forEach(function (action) {
          try {
            navigator.mediaSession.setActionHandler(action, function () { rec.seeks += 1; say(note.dataset.noSeek); });
          } catch (err) { /* an action this browser does not know */ }
        });
      }
    }
    document.addEventListener("visibilitychange", function () {
      if (document.hidden) {
        if (!video.paused && !video.ended) { rec.hidden += 1; hiddenSince = now(); }
        if (stallStart !== null) { rec.stall_ms += now() - stallStart; stallStart = null; }
        return;
      }
      if (hiddenSince !== null) { rec.hidden_ms += now() - hiddenSince; hiddenSince = null; }
      if (pausedByHiding && video.paused && !video.ended) { video.play(); }
      pausedByHiding = false;
    });
    video.addEventListener("error", function () { setEnabled(true); say(note.dataset.failed); }, true);
    // The script is deferred: the clip may have started, or even ended, before the listeners above existed.
    if (video.ended) {
      onPlaying();
      atEnd = true;
      markPlayed();
    } else if (!video.paused && video.readyState >= 2) {
      onPlaying();
    }
    updateButtons();
    if (video.autoplay && video.paused && !video.ended) {
      if (playRequested === null) { playRequested = now(); }
      var p = video.play();
      if (p && p.catch) {
        p.catch(function () { blocked = true; say(note.dataset.pressPlay); updateButtons(); });
      }
    } else if (!video.autoplay && playsSoFar() > 0) {
      say(replaysLeft() > 0 ? note.dataset.ready : note.dataset.noReplays);
    }
    video.addEventListener("canplaythrough", preloadNext);
    setTimeout(preloadNext, 4000);
    return function fillViewing() {
      answered = true;
      closeTimers();
      Object.keys(rec).forEach(function (key) {
        var input = form.querySelector("input[data-viewing][name='view_" + key + "']");
        if (input) { input.value = rec[key] === null ? "" : String(rec[key]); }
      });
    };
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

  // Digit key -> option. On a numbered scale (every option's value an integer: 0-4 Likert, 1-5 naturalness, 1-7
  // themes, -7..+7 inversion) the option showing that number, or none when no option shows it; a negative number is
  // the minus key and then the digit. On any other question the n-th option (1 = first).
  function numberedScale(inputs) {
    return inputs.length > 0 && Array.prototype.every.call(inputs, function (i) { return /^-?[0-9]+$/.test(i.value); });
  }

  function optionForDigit(inputs, n, negative) {
    if (numberedScale(inputs)) {
      var want = String(negative ? -n : n);
      if (negative && n === 0) { want = "0"; }
      return Array.prototype.find.call(inputs, function (i) { return String(Number(i.value)) === want; });
    }
    return !negative && n >= 1 ? inputs[n - 1] : undefined;
  }

  function choose(fs, n, active, negative) {
    var inputs = fs.querySelectorAll("input[type=radio], input[type=checkbox]");
    var input = optionForDigit(inputs, n, negative);
    if (!input || input.disabled || fs.disabled) { return false; }
    input.checked = input.type === "checkbox" ? !input.checked : true;
    input.dispatchEvent(new Event("change", { bubbles: true }));
    if (fs.contains(active)) { input.focus(); }
    var legend = fs.querySelector("legend");
    var label = input.closest("label");
    live.textContent = (legend ? legend.textContent.trim() + " " : "") + (label ? label.textContent.trim() : "");
    return true;
  }

  var MINUS_WINDOW_MS = 3000;   // a minus key counts for the next digit pressed within this time
  var minusAt = 0;

  function setUpKeys() {
    document.addEventListener("keydown", function (e) {
      if (e.altKey || e.ctrlKey || e.metaKey || e.defaultPrevented) { return; }
      var active = document.activeElement;
      if (isTyping(active)) { return; }
      if (e.key === "-") {
        var signed = targetQuestion(active);
        if (signed && signed.querySelector("input[value^='-']")) {
          minusAt = Date.now();
          live.textContent = "\u2212";
          e.preventDefault();
        }
        return;
      }
      if (/^[0-9]$/.test(e.key)) {
        var negative = Date.now() - minusAt < MINUS_WINDOW_MS;
        minusAt = 0;
        var fs = targetQuestion(active);
        if (fs && choose(fs, Number(e.key), active, negative)) { e.preventDefault(); }
        return;
      }
      minusAt = 0;
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
      if (fillViewing) { fillViewing(); }
      submit.disabled = false;
      setTimeout(function () { submit.disabled = true; }, 0);
    });
  }
})();
