// The page's drill sound: the AudioWorklet of drillsound-worklet.js fed with the parameters the
// server publishes in the trame state (vc_sound) while drilling. Reachable as window.vcDrillSound
// and, in templates, utils.vc.sound. The audio context starts on the sound switch (a user gesture,
// as browsers require); without Web Audio the page stays silent and says why.
(function () {
  const script = document.currentScript;
  const workletUrl = new URL("drillsound-worklet.js", script ? script.src : window.location.href).href;
  const SAMPLE_RATE = 48000;

  const sound = {
    context: null,
    node: null,
    config: null,
    volume: 0.5,
    parameters: null,
    message: "",
    // What arrived from the server: count, and transport delays (ms) from its stamp to here.
    received: 0,
    receivedAt: [],
    transportMs: [],
    pendingApplied: new Map(),
    nextId: 1,

    async start(volume) {
      if (volume !== undefined) this.volume = volume;
      if (this.context) return true;
      if (!window.AudioContext || !window.AudioWorkletNode) {
        this.message = "This browser has no Web Audio worklets: the drill sound is off.";
        return false;
      }
      try {
        const context = new AudioContext({ sampleRate: SAMPLE_RATE, latencyHint: "interactive" });
        await context.audioWorklet.addModule(workletUrl);
        this.node = new AudioWorkletNode(context, "vc-drill-sound", {
          numberOfInputs: 0, outputChannelCount: [1],
          processorOptions: { config: this.config, parameters: this.withVolume(this.parameters || {}) },
        });
        this.node.port.onmessage = (event) => this.onWorkletMessage(event.data);
        this.node.connect(context.destination);
        this.context = context;
        await context.resume();
        this.message = "";
        return true;
      } catch (error) {
        this.message = `The drill sound could not start: ${error}`;
        this.context = null;
        this.node = null;
        return false;
      }
    },

    async stop() {
      const context = this.context;
      this.context = null;
      this.node = null;
      if (context) await context.close();
    },

    withVolume(values) {
      return { ...values, volume: this.volume };
    },

    // The server's parameters (trame state vc_sound): {parameters, sent_at (ms since the epoch)}, and its
    // configuration (vc_sound_config), which the worklet takes when it starts.
    update(state, config) {
      if (!state || !state.parameters) return;
      this.received += 1;
      const now = Date.now();
      this.receivedAt.push(performance.now());
      if (state.sent_at) this.transportMs.push(now - state.sent_at);
      if (this.receivedAt.length > 2000) this.receivedAt.shift();
      if (this.transportMs.length > 2000) this.transportMs.shift();
      if (config) this.config = config;
      this.parameters = state.parameters;
      this.post(this.parameters);
    },

    setVolume(volume) {
      this.volume = Math.min(1, Math.max(0, Number(volume)));
      if (this.parameters) this.post(this.parameters);
    },

    // Send parameters to the worklet; resolves with {frame, postedAt} once it renders with them.
    post(values) {
      if (!this.node) return null;
      const id = this.nextId++;
      const postedAt = performance.now();
      const applied = new Promise((resolve) => this.pendingApplied.set(id, { resolve, postedAt }));
      this.node.port.postMessage({ type: "parameters", values: this.withVolume(values), id });
      return applied;
    },

    onWorkletMessage(message) {
      if (!message || message.type !== "applied") return;
      const waiting = this.pendingApplied.get(message.id);
      if (!waiting) return;
      this.pendingApplied.delete(message.id);
      waiting.resolve({ ...message, postedAt: waiting.postedAt, answeredAt: performance.now() });
    },

    // Render the worklet offline: schedule [[time_s, parameters], ...] from a steady start; returns the samples.
    async renderOffline(schedule, seconds, config, steady = true) {
      const frames = Math.round(seconds * SAMPLE_RATE);
      const context = new OfflineAudioContext(1, frames, SAMPLE_RATE);
      await context.audioWorklet.addModule(workletUrl);
      const node = new AudioWorkletNode(context, "vc-drill-sound", {
        numberOfInputs: 0, outputChannelCount: [1],
        processorOptions: { config, parameters: schedule[0][1], schedule: schedule.slice(1), steady },
      });
      node.connect(context.destination);
      const buffer = await context.startRendering();
      return Array.from(buffer.getChannelData(0));
    },

    // Time (ms) from a parameter change in the page to the changed sound at the output, in the live context:
    // until the worklet renders with it (by the audio clock, mapped to the page's clock through
    // getOutputTimestamp, which includes the output latency), for `trials` changes between two sets.
    async measureLatency(before, after, trials = 20) {
      if (!this.context) throw new Error("the sound is off");
      const results = [];
      const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
      for (let i = 0; i < trials; i++) {
        await this.post(i % 2 ? after : before);
        await sleep(30 + 7 * (i % 5));
        const changedAt = performance.now();
        const applied = await this.post(i % 2 ? before : after);
        const stamp = this.context.getOutputTimestamp();
        const outputLatency = (this.context.outputLatency || 0) + (this.context.baseLatency || 0);
        let heardAt;
        if (stamp && stamp.performanceTime > 0) {
          heardAt = stamp.performanceTime + (applied.frame / this.context.sampleRate - stamp.contextTime) * 1000;
        } else {
          heardAt = applied.answeredAt + outputLatency * 1000;
        }
        results.push({ latencyMs: heardAt - changedAt, postToAnswerMs: applied.answeredAt - changedAt,
                       outputLatencyMs: outputLatency * 1000, viaTimestamp: !!(stamp && stamp.performanceTime > 0) });
      }
      return results;
    },

    // Updates per second over the last `windowMs` of arrivals.
    rate(windowMs = 1000) {
      const now = performance.now();
      return this.receivedAt.filter((t) => now - t <= windowMs).length * (1000 / windowMs);
    },
  };

  window.vcDrillSound = sound;
  (function register(attempts) {
    const trame = window.trame;
    if (!trame || !trame.utils || !trame.utils.vc || !trame.state || !trame.state.watch) {
      if (attempts > 0) setTimeout(() => register(attempts - 1), 10);  // a page without trame: stop after 30 s
      return;
    }
    trame.utils.vc.sound = sound;
    // Watched here, not in the page's template: a template that reads vc_sound renders again at each update.
    trame.state.watch(["vc_sound", "vc_sound_config"], (state, config) => sound.update(state, config));
  })(3000);
})();
