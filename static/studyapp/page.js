/* Instruction and break pages (templates/studyapp/page.html, studyapp/participant/views_pages.py). On a break page the Continue
   button stays disabled until the wait has passed, counting down the seconds the server wrote into
   #page-wait's data-wait-left (the time left since the page's first display, so a reload continues the count);
   the sentences come from its data attributes, in the study's language. The server refuses an early Continue
   itself; without this script the button is always enabled. On every page the button is disabled after the
   first click, so a double click sends one Continue. */
(function () {
  "use strict";
  var form = document.getElementById("page-form");
  var button = document.getElementById("continue");
  if (!form || !button) { return; }
  form.addEventListener("submit", function (event) {
    if (button.disabled) { event.preventDefault(); return; }
    window.setTimeout(function () { button.disabled = true; }, 0);
  });
  var note = document.getElementById("page-wait");
  if (!note) { return; }
  var end = Date.now() + 1000 * (Number(note.dataset.waitLeft) || 0);

  function tick() {
    var left = Math.ceil((end - Date.now()) / 1000);
    if (left <= 0) {
      button.disabled = false;
      note.setAttribute("aria-live", "polite");     // announce the end of the wait, not every second of it
      note.textContent = note.dataset.ready;
      return;
    }
    button.disabled = true;
    note.textContent = left === 1 ? note.dataset.one : note.dataset.many.replace("{n}", String(left));
    window.setTimeout(tick, Math.max(50, end - Date.now() - 1000 * (left - 1)));
  }
  tick();
}());
