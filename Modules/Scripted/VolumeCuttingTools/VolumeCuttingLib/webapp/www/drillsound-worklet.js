// The drill sound in the browser: an AudioWorklet processor implementing the model of
// VolumeCuttingLib/feedback/drillsound.py with the same constants and the same per-sample
// equations (one-pole glides, one phase for all partials, counter-hashed noise, the monitor's
// click clock), so that the page sounds as the desktop does. The tests render both and compare.
//
// Messages on the port: {type: "parameters", values, id} takes effect at the next render
// quantum and is answered by {type: "applied", id, frame} (the first frame rendered with it).
// processorOptions: {config, parameters, schedule: [[time_s, values], ...], steady}.

const SAMPLE_RATE_DEFAULT = 48000;
const CONTROL_PERIOD = 64;
const HEADROOM = 0.9;
const MOTOR_STOPPED_HZ = 0.5;
const TONE_BUDGET = 0.55;
const HISS_BUDGET = 0.1;
const CLICK_BUDGET = HEADROOM - TONE_BUDGET - HISS_BUDGET;
const IDLE_GAIN = 0.25;
const CLICK_GAIN = { silent: 0.0, sparse: 0.6, bursts: 0.75, continuous: 0.85, contact: 1.0 };
const CLICKS_PER_BURST = 4;
const BURST_SPACING_S = 0.005;
const CLICK_FREQUENCY = 1800.0;
const CLICK_DECAY_S = 0.0008;
const CLICK_LENGTH_S = 0.004;
const SMEAR_SEED = 0x2545f491;
const HISS_SEED = 0x9e3779b9;
const SPECTRA = {
  idle: { partials: { 1: 1.0, 2: 0.3, 3: 0.12 }, smear: 0.1, hiss: 0.1 },
  cutting: { partials: { 1: 1.0, 2: 0.5, 3: 0.35, 4: 0.25, 6: 0.8, 8: 0.2, 12: 0.5 }, smear: 0.25, hiss: 0.25 },
  diamond: { partials: { 1: 1.0, 2: 0.35, 3: 0.15, 4: 0.08 }, smear: 0.7, hiss: 0.45 },
};
const SPECTRUM_NAMES = ["idle", "cutting", "diamond"];
const HARMONICS = [...new Set(SPECTRUM_NAMES.flatMap((n) => Object.keys(SPECTRA[n].partials).map(Number)))].sort((a, b) => a - b);
const DEFAULT_CONFIG = {
  sample_rate: SAMPLE_RATE_DEFAULT, load_pitch_drop: 0.15, thin_bone_mm: 2.0, thin_pitch_rise: 0.25,
  spin_up_s: 0.15, spin_down_s: 0.35, glide_s: 0.002, full_load_removal_mm3_s: 20.0,
};
const DEFAULT_PARAMETERS = {
  rpm: 60000.0, drill_on: false, burr: "cutting", contact: false, load: 0.0, thickness_mm: -1.0,
  monitor_level: "silent", monitor_rate_hz: 0.0, volume: 1.0,
};

// lowbias32 of (counter + seed), in [0, 1): drillsound.hashed_uniform.
function hashedUniform(seed, counter) {
  let x = (counter + seed) >>> 0;
  x ^= x >>> 16;
  x = Math.imul(x, 0x7feb352d) >>> 0;
  x ^= x >>> 15;
  x = Math.imul(x, 0x846ca68b) >>> 0;
  x ^= x >>> 16;
  return (x >>> 0) / 4294967296.0;
}

// The parameters checked as SoundParameters checks them; a bad value keeps the previous set.
function validParameters(values) {
  const p = { ...DEFAULT_PARAMETERS, ...values };
  const finite = (v, lo, hi) => typeof v === "number" && Number.isFinite(v) && v >= lo && v <= hi;
  const thickness = p.thickness_mm;
  if (!finite(p.rpm, 0, 150000) || !finite(p.load, 0, 1) || !finite(p.monitor_rate_hz, 0, 1000) ||
      !finite(p.volume, 0, 1) || !(thickness === -1 || thickness === null || finite(thickness, 0, Infinity)) ||
      !(p.burr in { cutting: 1, diamond: 1 }) || !(p.monitor_level in CLICK_GAIN)) {
    return null;
  }
  p.thickness_mm = thickness === -1 || thickness === null ? Infinity : thickness;
  p.drill_on = !!p.drill_on;
  p.contact = !!p.contact;
  return p;
}

class DrillSoundModel {
  constructor(config, parameters) {
    this.config = { ...DEFAULT_CONFIG, ...(config || {}) };
    const rate = this.config.sample_rate;
    this.parameters = validParameters(parameters || {}) || validParameters({});
    this.ratioUp = Math.exp(-1.0 / (this.config.spin_up_s * rate));
    this.ratioDown = Math.exp(-1.0 / (this.config.spin_down_s * rate));
    this.ratioGlide = Math.exp(-1.0 / (this.config.glide_s * rate));
    this.motorHz = 0.0;
    this.referenceHz = this.parameters.rpm / 60.0;
    this.pitch = 1.0;
    this.gains = { idle: 0.0, cutting: 0.0, diamond: 0.0, click: 0.0, volume: this.parameters.volume };
    this.phase = 0.0;
    this.clickPhase = 0.0;
    this.clicksActive = false;
    this.clickRing = new Float64Array(8192);
    this.samplesRendered = 0;
    this.amplitudes = {};
    for (const name of SPECTRUM_NAMES) {
      const partials = SPECTRA[name].partials;
      const raw = HARMONICS.map((k) => partials[k] || 0.0);
      const sum = raw.reduce((a, b) => a + b, 0);
      this.amplitudes[name] = raw.map((a) => (a * TONE_BUDGET) / sum);
    }
    const length = Math.floor(CLICK_LENGTH_S * rate);
    this.clickShape = new Float64Array(length);
    let peak = 0;
    for (let j = 0; j < length; j++) {
      const t = j / rate;
      this.clickShape[j] = Math.sin(2 * Math.PI * CLICK_FREQUENCY * t) * Math.exp(-t / CLICK_DECAY_S);
      peak = Math.max(peak, Math.abs(this.clickShape[j]));
    }
    for (let j = 0; j < length; j++) this.clickShape[j] /= peak;
    this.burstOffsets = [...Array(CLICKS_PER_BURST).keys()].map((i) => Math.floor(i * BURST_SPACING_S * rate));
    // Scratch arrays for one block.
    this.motor = new Float64Array(0);
  }

  setParameters(values) {
    const p = validParameters(values);
    if (p) this.parameters = p;
    return !!p;
  }

  loadFactor(p) {
    return 1.0 - this.config.load_pitch_drop * (p.contact ? p.load : 0.0);
  }

  thinningFactor(thickness) {
    const c = this.config;
    if (!Number.isFinite(thickness) || thickness >= c.thin_bone_mm) return 1.0;
    return 1.0 + c.thin_pitch_rise * (1.0 - thickness / c.thin_bone_mm);
  }

  targets() {
    const p = this.parameters;
    const engaged = p.drill_on && p.contact;
    return {
      idle: !engaged && (p.drill_on || this.motorHz > 0.0) ? IDLE_GAIN : 0.0,
      cutting: engaged && p.burr === "cutting" ? 1.0 : 0.0,
      diamond: engaged && p.burr === "diamond" ? 1.0 : 0.0,
      click: p.monitor_rate_hz > 0.0 ? CLICK_GAIN[p.monitor_level] : 0.0,
      volume: p.volume,
    };
  }

  settle() {
    const p = this.parameters;
    this.motorHz = p.drill_on ? p.rpm / 60.0 : 0.0;
    this.referenceHz = p.rpm / 60.0;
    this.pitch = this.loadFactor(p) * this.thinningFactor(p.thickness_mm);
    Object.assign(this.gains, this.targets());
  }

  // The next out.length samples into out (Float32Array), as DrillSoundRenderer.render.
  render(out) {
    const frames = out.length;
    const p = this.parameters;
    const rate = this.config.sample_rate;
    const glide = (current, target, ratio) => {
      const values = new Float64Array(frames);
      let factor = ratio;
      for (let i = 0; i < frames; i++) {
        values[i] = current === target ? target : target + (current - target) * factor;
        factor *= ratio;
      }
      return values;
    };
    const motorTarget = p.drill_on ? p.rpm / 60.0 : 0.0;
    const motor = glide(this.motorHz, motorTarget, motorTarget > this.motorHz ? this.ratioUp : this.ratioDown);
    const pitch = glide(this.pitch, this.loadFactor(p) * this.thinningFactor(p.thickness_mm), this.ratioGlide);
    this.motorHz = motor[frames - 1];
    this.pitch = pitch[frames - 1];
    if (motorTarget === 0.0 && this.motorHz < MOTOR_STOPPED_HZ) this.motorHz = 0.0;
    if (p.rpm > 0.0) this.referenceHz = p.rpm / 60.0;
    const gains = {};
    const targets = this.targets();
    for (const name of Object.keys(targets)) {
      gains[name] = glide(this.gains[name], targets[name], this.ratioGlide);
      this.gains[name] = gains[name][frames - 1];
    }
    const clicks = this.clicks(frames);
    const active = SPECTRUM_NAMES.filter((name) => gains[name].some((g) => g !== 0.0));
    const count = HARMONICS.length;
    const first = this.samplesRendered;
    let phase = this.phase;
    for (let i = 0; i < frames; i++) {
      const fundamental = motor[i] * pitch[i];
      phase += fundamental / rate;
      let value = clicks[i] * gains.click[i] * CLICK_BUDGET;
      if (active.length) {
        const speedFraction = this.referenceHz > 0.0 ? Math.min(1.0, Math.max(0.0, motor[i] / this.referenceHz)) : 0.0;
        const sample = first + i;
        const draw = Math.floor(sample / CONTROL_PERIOD);
        const fraction = (sample % CONTROL_PERIOD) / CONTROL_PERIOD;
        let tone = 0.0;
        let hissGain = 0.0;
        for (const name of active) hissGain += gains[name][i] * SPECTRA[name].hiss;
        for (let h = 0; h < count; h++) {
          const before = hashedUniform(SMEAR_SEED, draw * count + h);
          const after = hashedUniform(SMEAR_SEED, (draw + 1) * count + h);
          const smear = before + (after - before) * fraction;
          let amplitude = 0.0;
          for (const name of active) {
            amplitude += gains[name][i] * this.amplitudes[name][h] * (1.0 - SPECTRA[name].smear * smear);
          }
          const k = HARMONICS[h];
          const fade = Math.min(1.0, Math.max(0.0, (0.46 * rate - k * fundamental) / (0.06 * rate)));
          tone += amplitude * fade * speedFraction * Math.sin(2.0 * Math.PI * k * phase + k);
        }
        const hiss = hashedUniform(HISS_SEED, sample) - hashedUniform(HISS_SEED, sample - 1);
        value += tone + hissGain * speedFraction * HISS_BUDGET * hiss;
      }
      out[i] = gains.volume[i] * value;
    }
    this.phase = phase % 1.0;
    this.samplesRendered += frames;
  }

  // The monitor's clicks of the next frames (before gain), as DrillSoundRenderer._clicks.
  clicks(frames) {
    const p = this.parameters;
    const ring = this.clickRing;
    const size = ring.length;
    const first = this.samplesRendered;
    const active = p.monitor_level !== "silent" && p.monitor_rate_hz > 0.0;
    if (active && !this.clicksActive) this.clickPhase = 1.0 - Number.EPSILON / 2;
    this.clicksActive = active;
    if (active) {
      const bursts = p.monitor_level === "bursts";
      const step = p.monitor_rate_hz / (bursts ? CLICKS_PER_BURST : 1) / this.config.sample_rate;
      const offsets = bursts ? this.burstOffsets : this.burstOffsets.slice(0, 1);
      const overlap = bursts ? 1 : Math.max(1, Math.ceil(p.monitor_rate_hz * CLICK_LENGTH_S));
      let previous = this.clickPhase;
      for (let i = 0; i < frames; i++) {
        const clock = this.clickPhase + step * (i + 1);
        if (Math.floor(clock) > Math.floor(previous)) {
          for (const offset of offsets) {
            const at = first + i + offset;
            for (let j = 0; j < this.clickShape.length; j++) ring[(at + j) % size] += this.clickShape[j] / overlap;
          }
        }
        previous = clock;
      }
      this.clickPhase = previous % 1.0;
    }
    const out = new Float64Array(frames);
    for (let i = 0; i < frames; i++) {
      const slot = (first + i) % size;
      out[i] = Math.min(1.0, Math.max(-1.0, ring[slot]));
      ring[slot] = 0.0;
    }
    return out;
  }
}

if (typeof AudioWorkletProcessor !== "undefined") {
  class DrillSoundProcessor extends AudioWorkletProcessor {
    constructor(options) {
      super();
      const o = (options && options.processorOptions) || {};
      this.model = new DrillSoundModel(o.config, o.parameters);
      if (o.steady) this.model.settle();
      this.schedule = (o.schedule || []).slice();
      this.pending = null;
      this.port.onmessage = (event) => {
        const message = event.data || {};
        if (message.type === "parameters") this.pending = message;
      };
    }

    process(inputs, outputs) {
      const rate = this.model.config.sample_rate;
      while (this.schedule.length && this.schedule[0][0] * rate <= this.model.samplesRendered) {
        this.model.setParameters(this.schedule.shift()[1]);
      }
      if (this.pending) {
        const message = this.pending;
        this.pending = null;
        const accepted = this.model.setParameters(message.values);
        if (message.id !== undefined) {
          this.port.postMessage({ type: "applied", id: message.id, accepted, frame: currentFrame, time: currentTime });
        }
      }
      const channel = outputs[0][0];
      this.model.render(channel);
      for (let c = 1; c < outputs[0].length; c++) outputs[0][c].set(channel);
      return true;
    }
  }
  registerProcessor("vc-drill-sound", DrillSoundProcessor);
}
