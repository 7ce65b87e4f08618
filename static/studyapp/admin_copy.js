/* Copy buttons of the staff pages: <button class="copy-button" data-copy="ID"> copies the value (or text) of the
   element ID to the clipboard and says so on the button. No inline script: the pages carry a CSP. */
(function () {
  "use strict";
  document.addEventListener("click", function (event) {
    var button = event.target.closest ? event.target.closest(".copy-button") : null;
    if (!button) { return; }
    var source = document.getElementById(button.getAttribute("data-copy"));
    if (!source) { return; }
    var text = "value" in source ? source.value : source.textContent;
    var done = function () {
      var label = button.textContent;
      button.textContent = "Copied";
      setTimeout(function () { button.textContent = label; }, 1500);
    };
    if (navigator.clipboard && navigator.clipboard.writeText) {
      navigator.clipboard.writeText(text).then(done, function () {
        if (source.select) { source.select(); }
      });
    } else if (source.select) {
      source.select();
      document.execCommand("copy");
      done();
    }
  });
})();
