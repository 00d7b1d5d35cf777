/* `liganimate view --watch`: reload when the program is saved, keeping the view.
 *
 * Asks the local server (127.0.0.1, the one that served this page) for the
 * program's version four times a second. A new version reloads the page,
 * with the scene, the frame and the camera kept in sessionStorage; a
 * program that is wrong shows its diagnostic (file:line:col, the line, the
 * hint) over the last good picture instead of a blank page.
 */
'use strict';
(function () {
  var KEY = 'lig-watch-view';
  var known = null;
  var box = document.getElementById('lig-diagnostic');
  var viewer = window.ligViewer;
  if (viewer) {
    try {
      var kept = JSON.parse(sessionStorage.getItem(KEY) || 'null');
      if (kept) viewer.restore(kept);
    } catch (err) { /* a view from another page: start afresh */ }
  }
  function show(error) {
    box.textContent = error || '';
    box.hidden = !error;
  }
  function poll() {
    fetch('/watch', { cache: 'no-store' }).then(function (r) { return r.json(); }).then(function (w) {
      if (known === null) known = w.version;
      if (w.version !== known && !w.error) {
        if (viewer) sessionStorage.setItem(KEY, JSON.stringify(viewer.view()));
        location.reload();
        return;
      }
      show(w.error);
      setTimeout(poll, 250);
    }).catch(function () {
      show('the liganimate view --watch server has stopped');
      setTimeout(poll, 1000);
    });
  }
  poll();
})();
