// Client helpers of the VolumeCutting web application, reachable in templates as utils.vc.
// Files are checked here before anything is sent: a file over the size limit
// is refused at once with a message instead of being transferred first.
(function register() {
  if (!window.trame || !window.trame.utils) {
    setTimeout(register, 10);
    return;
  }
  function megabytes(bytes) {
    return (bytes / (1024 * 1024)).toFixed(1);
  }
  window.trame.utils.vc = {
    // Send the chosen files to the server (trigger "vc_upload"); returns the
    // message to show now: empty when they were sent.
    upload(kind, files, maxBytes) {
      const list = Array.isArray(files) ? files : files ? [files] : [];
      if (!list.length) {
        return "";
      }
      const total = list.reduce((sum, file) => sum + file.size, 0);
      if (total > maxBytes) {
        const names = list.length === 1 ? list[0].name : `${list.length} files`;
        return `${names}: ${megabytes(total)} MB is more than this server accepts ` +
          `(${megabytes(maxBytes)} MB). Ask the administrator to raise --max-upload-mb, ` +
          `or give the path of the file on the server.`;
      }
      window.trame.trigger("vc_upload", [kind, list]);
      return "";
    },
    // The instructor link of this session: the address of the server this page is connected to (the
    // session's own process, also behind the launcher), with the instructor's key.
    instructorLink(key) {
      if (!key) {
        return "";
      }
      let origin = window.location.origin;
      const url = window.trame.client?.getConnection?.()?.getUrl?.();
      if (url) {
        const ws = new URL(url);
        origin = `${ws.protocol === "wss:" ? "https:" : "http:"}//${ws.host}`;
      }
      return `${origin}/instructor?key=${encodeURIComponent(key)}`;
    },
    // [tool, fx, fy, depth]: a click on the instructor's pick layer as fractions of the 3D view's picture under
    // it (0 at the left and bottom), which the server turns into the surface point there.
    pickArguments(tool, event, depth) {
      const image = document.elementsFromPoint(event.clientX, event.clientY).find((e) => e.tagName === "IMG");
      const box = (image || event.currentTarget).getBoundingClientRect();
      return [tool, (event.clientX - box.left) / box.width, 1 - (event.clientY - box.top) / box.height, depth];
    },
  };
})();
