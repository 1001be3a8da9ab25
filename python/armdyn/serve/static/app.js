// armdyn serve: the student's page. Plain JS, loaded from this server only (the CSP
// allows no inline script). The preview HTML comes from the server, already
// sanitized (MathML whitelist, text escaped); it is parsed into an inert template
// before it is shown.
"use strict";

(function () {
  function $(id) { return document.getElementById(id); }
  // server HTML (already sanitized) into an element, through an inert template
  function inert(el, html) {
    var t = document.createElement("template");
    t.innerHTML = html;
    el.replaceChildren(t.content);
  }

  // -- live preview: debounced, one request in flight, the newest text wins
  var text = $("markdown"), box = $("preview"), state = $("preview-state"), exercise = $("exercise");
  if (text && box) {
    var timer = null, inflight = false, again = false;
    var show = function (html) { inert(box, html); };
    var run = function () {
      if (inflight) { again = true; return; }
      inflight = true; again = false;
      state.textContent = "(reading…)";
      var url = "/api/preview" + (exercise && exercise.value ? "?exercise=" + encodeURIComponent(exercise.value) : "");
      fetch(url, {method: "POST", headers: {"Content-Type": "text/markdown"}, body: text.value})
        .then(function (r) {
          // a busy server says when to come back (Retry-After): the preview tries once more then
          var wait = r.status === 503 ? parseInt(r.headers.get("Retry-After") || "", 10) : NaN;
          if (wait > 0 && wait <= 60) { clearTimeout(timer); timer = setTimeout(run, wait * 1000); }
          return r.json().then(function (j) { return [r.ok, j]; });
        })
        .then(function (res) {
          if (res[0]) {
            show(res[1].html);
            var n = box.querySelectorAll(".step:not(.none)").length;
            state.textContent = "(" + n + (n === 1 ? " step" : " steps") + " read)";
          }
          else { state.textContent = "(" + (res[1].error || "preview unavailable") + ")"; }
        })
        .catch(function () { state.textContent = "(offline)"; })
        .finally(function () { inflight = false; if (again) { schedule(); } });
    };
    var schedule = function () { clearTimeout(timer); timer = setTimeout(run, 400); };
    text.addEventListener("input", schedule);
    if (exercise) { exercise.addEventListener("change", schedule); }

    // -- the problem statement of the chosen exercise
    var statement = $("statement");
    if (exercise && statement) {
      var load = function () {
        if (!exercise.value) {
          statement.replaceChildren();
          var p = document.createElement("p");
          p.textContent = "Choose an exercise to see its statement.";
          statement.appendChild(p);
          return;
        }
        fetch("/exercises/" + encodeURIComponent(exercise.value) + "/statement")
          .then(function (r) { return r.ok ? r.text() : Promise.reject(r.status); })
          .then(function (html) { inert(statement, html); statement.scrollTop = 0; })
          .catch(function () { statement.textContent = "The statement could not be loaded."; });
      };
      exercise.addEventListener("change", load);
      // a menu the browser restored (back button) to another exercise than the page's
      var preset = exercise.querySelector("option[selected]");
      if (exercise.value !== (preset ? preset.value : "")) { load(); }
    }
    if (text.value) { schedule(); }

    // -- upload: read the file into the text area (and preview it)
    var upload = $("upload");
    if (upload) {
      upload.addEventListener("change", function () {
        var f = upload.files && upload.files[0];
        if (!f) { return; }
        f.text().then(function (t) { text.value = t; upload.value = ""; schedule(); });
      });
    }
    var form = $("grade-form"), button = $("grade-button");
    if (form && button) {
      form.addEventListener("submit", function () {
        button.disabled = true;
        button.textContent = "Grading…";
        var said = $("grade-state");
        if (said) { said.textContent = "Sent: grading every step, this takes a few seconds…"; }
      });
    }
  }

  // -- a submission still being graded: poll, reload when it is done
  var sub = $("submission");
  if (sub && (sub.dataset.status === "queued" || sub.dataset.status === "running")) {
    var url = "/api/submissions/" + encodeURIComponent(sub.dataset.id)
      + (sub.dataset.token ? "?t=" + encodeURIComponent(sub.dataset.token) : "");
    var pending = $("pending"), shown = pending ? pending.textContent : "";
    var waiting = function (position) {
      return position ? "Waiting in the queue: number " + position + " (1 is graded next)… this page updates by itself."
        : "Waiting in the queue… this page updates by itself.";
    };
    var poll = function () {
      fetch(url, {credentials: "same-origin"}).then(function (r) { return r.json(); }).then(function (j) {
        if (j.status === "done" || j.status === "failed") { window.location.reload(); return; }
        var said = j.status === "running" ? "Grading now… this page updates by itself."
          : waiting(j.position);
        if (pending && said !== shown) {  // the live region says when grading starts, or the queue moves
          shown = said;
          pending.textContent = said;
        }
        setTimeout(poll, 1000);
      }).catch(function () { setTimeout(poll, 3000); });
    };
    setTimeout(poll, 1000);
  }
})();
