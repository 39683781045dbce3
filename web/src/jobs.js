// Following a server job to its end: job.progress/job.done over the websocket, with polling
// as the fallback when the live connection is unavailable (and, slowly, as a backstop).
const POLL_MS = 300;
const POLL_BACKSTOP_MS = 2000;
const FINISHED = ['succeeded', 'failed', 'cancelled'];

export function finished(job) {
  return FINISHED.includes(job?.status);
}

// Calls onUpdate(job) for each progress report; resolves with the finished job
// ({id, status, result, error}).
export function followJob(editor, api, live, job, onUpdate = () => {}) {
  const id = job.id;
  return new Promise((resolve) => {
    let done = false;
    let timer = 0;
    let lastLive = 0;
    const finish = (j) => {
      if (done) return;
      done = true;
      clearTimeout(timer);
      live.unwatch(id);
      resolve(j);
    };
    const update = (j) => {
      if (done) return;
      if (finished(j)) finish(j);
      else onUpdate(j);
    };
    const poll = async () => {
      if (done) return;
      const quiet = Date.now() - lastLive;
      if (!live.open || quiet >= POLL_BACKSTOP_MS) {
        try {
          update(await api.getJob(id));
        } catch (err) {
          editor.fail(err);
          finish({ ...job, status: 'failed', error: err.problem });
          return;
        }
      }
      if (!done) timer = setTimeout(poll, live.open ? POLL_BACKSTOP_MS : POLL_MS);
    };
    live.connect().catch(() => {
      // polling carries on alone
    });
    live.watch(id, (msg) => {
      lastLive = Date.now();
      if (msg.type === 'job.done') finish({ id, kind: job.kind, status: msg.status, result: msg.result, error: msg.error });
      else update({ id, kind: job.kind, status: msg.status, progress: msg.progress, stage: msg.stage });
    });
    timer = setTimeout(poll, POLL_MS);
  });
}
