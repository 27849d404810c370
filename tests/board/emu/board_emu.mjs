#!/usr/bin/env node
// The cbvh board (RP2040 + iCE40UP5K, pico-ice layout) run on an emulated
// RP2040 (rp2040js): this harness is the boot ROM, the FPGA and the USB host.
//
//   node board_emu.mjs --uf2 IMG.uf2 --bitstream BITS.bin --regmap PROG
//                      [--protocol docs/protocol.md] [options] check|serve
//
// It loads the UF2 the build wrote, checks boot2's CRC and starts boot2 as the
// boot ROM would (boot2 then enters the image); it serves SPI1 as the iCE40's
// configuration port (CRESET_B/SS timing, the exact bitstream bytes, the
// trailing clocks, then CDONE) and SPI0 as the FPGA's register map, answered
// by PROG (board_emu_regmap: the bit-exact model's register map behind two
// named pipes); it is the USB host through rp2040js's USB controller:
// enumerates, checks every descriptor against docs/protocol.md, and moves
// the board protocol's bytes over the bulk pair or, with --link hid, the HID
// reports.
//
//   check   boot, enumerate, configure, then IDENTIFY/LOOPBACK/STATUS over
//           both links; with --usb-abuse also malformed and random setup
//           packets, an oversized flood, and a host that vanishes mid-transfer.
//           Prints one line per check, 'N passed, M failed', exit 0 or 1.
//   serve   the same boot, then bridges the chosen link to a unix socket
//           (--listen PATH) that `cbvh ... --backend sim:unix:PATH` reaches;
//           --ready FILE is written once it listens; --reset-after-bytes N
//           resets the chip once N reply bytes have gone to the host.
//
// Other options: --cdone-low (the FPGA never raises CDONE), --no-bitstream
// (the UF2's bitstream region is left out), --corrupt-boot2 (flip a bit of
// boot2: the boot ROM must refuse it), --stats FILE (JSON figures at exit).
// Bad options: one line on stderr, exit 2.
import { execFileSync, spawn } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';

import { RP2040 } from 'rp2040js';

const me = 'board_emu';
const FLASH = 0x10000000;
const BITSTREAM_REGION = 0x10100000;
const BOOT2_SRAM = 0x20041f00;
const VID = 0x1209;
const PID = 0xc0b1;

// ---------------------------------------------------------------- options
function usage(msg) {
  process.stderr.write(`${me}: ${msg} (see the header of board_emu.mjs)\n`);
  process.exit(2);
}

function parseArgs(argv) {
  const o = { link: 'bulk', mode: null, resetAfterBytes: 0 };
  const valued = ['--uf2', '--bitstream', '--regmap', '--protocol', '--link', '--listen', '--ready',
    '--reset-after-bytes', '--stats'];
  const flags = ['--cdone-low', '--no-bitstream', '--corrupt-boot2', '--usb-abuse', '--quiet'];
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (valued.includes(a)) {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      o[a.slice(2).replace(/-([a-z])/g, (_, c) => c.toUpperCase())] = argv[++i];
    } else if (flags.includes(a)) {
      o[a.slice(2).replace(/-([a-z])/g, (_, c) => c.toUpperCase())] = true;
    } else if ((a === 'check' || a === 'serve') && !o.mode) {
      o.mode = a;
    } else {
      usage(`unknown argument '${a}'`);
    }
  }
  if (!o.mode) usage('expected check or serve');
  if (!o.uf2) usage('--uf2 is required');
  if (!o.regmap) usage('--regmap is required');
  if (!o.bitstream && !o.noBitstream) usage('--bitstream is required (or --no-bitstream)');
  if (o.link !== 'bulk' && o.link !== 'hid') usage(`--link expects bulk or hid, got '${o.link}'`);
  if (o.mode === 'serve' && !o.listen) usage('serve needs --listen PATH');
  if (o.resetAfterBytes !== 0) {
    if (!/^[0-9]+$/.test(o.resetAfterBytes)) usage(`--reset-after-bytes expects a byte count, got '${o.resetAfterBytes}'`);
    o.resetAfterBytes = Number(o.resetAfterBytes);
  }
  for (const f of ['uf2', 'bitstream', 'regmap', 'protocol']) {
    if (o[f] && !fs.existsSync(o[f])) usage(`--${f}: no such file '${o[f]}'`);
  }
  return o;
}

// ---------------------------------------------------------------- checks
const results = { passed: 0, failed: 0 };
let quiet = false;
function check(ok, what, detail = '') {
  if (ok) results.passed++;
  else results.failed++;
  if (!ok || !quiet) console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${detail ? ` (${detail})` : ''}`);
  return ok;
}

// ---------------------------------------------------------------- CRCs
function crc32Boot2(bytes) { // RP2040 datasheet 2.8.1.3.1: poly 04C11DB7, MSB first, init ~0, no xorout
  let c = 0xffffffff;
  for (const b of bytes) {
    c ^= b << 24;
    for (let k = 0; k < 8; k++) c = c & 0x80000000 ? (c << 1) ^ 0x04c11db7 : c << 1;
  }
  return c >>> 0;
}

const crcTable = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();
function crc32(bytes) { // IEEE 802.3, as the board protocol's frames
  let c = 0xffffffff;
  for (const b of bytes) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// ---------------------------------------------------------------- UF2
function loadUf2(file) {
  const buf = fs.readFileSync(file);
  if (buf.length === 0 || buf.length % 512) throw new Error(`${file}: not a UF2 file (${buf.length} bytes)`);
  const parts = [];
  for (let off = 0; off < buf.length; off += 512) {
    const b = buf.subarray(off, off + 512);
    const u = (i) => b.readUInt32LE(i);
    if (u(0) !== 0x0a324655 || u(4) !== 0x9e5d5157 || u(508) !== 0x0ab16f30) {
      throw new Error(`${file}: block ${off / 512} has bad UF2 magic numbers`);
    }
    if (!(u(8) & 0x2000) || u(28) !== 0xe48bff56) throw new Error(`${file}: block ${off / 512} is not for the RP2040`);
    const size = u(16);
    if (size > 476 || u(12) < FLASH || u(12) + size > FLASH + 16 * 1024 * 1024) {
      throw new Error(`${file}: block ${off / 512} writes outside flash`);
    }
    parts.push({ addr: u(12), data: Buffer.from(b.subarray(32, 32 + size)), no: u(20), count: u(24) });
  }
  const count = parts[0].count;
  if (parts.some((p, i) => p.no !== i || p.count !== count) || parts.length !== count) {
    throw new Error(`${file}: blocks out of order or missing (${parts.length} of ${count})`);
  }
  return parts;
}

// ---------------------------------------------------------------- register map helper (pipes)
class Regmap {
  constructor(prog) {
    this.dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cbvh-emu-'));
    const req = path.join(this.dir, 'req');
    const resp = path.join(this.dir, 'resp');
    execFileSync('mkfifo', [req, resp]);
    this.child = spawn(prog, [req, resp], { stdio: ['ignore', 'inherit', 'inherit'] });
    this.child.on('exit', (code) => {
      if (!this.closing) {
        process.stderr.write(`${me}: the register-map helper ended (exit ${code})\n`);
        process.exit(1);
      }
    });
    process.on('exit', () => fs.rmSync(this.dir, { recursive: true, force: true }));
    this.wfd = fs.openSync(req, 'w');
    this.rfd = fs.openSync(resp, 'r');
    this.msg = Buffer.alloc(9);
    this.reads = 0;
    this.writes = 0;
  }
  send(op, addr, value) {
    this.msg[0] = op;
    this.msg.writeUInt32LE(addr >>> 0, 1);
    this.msg.writeUInt32LE(value >>> 0, 5);
    fs.writeSync(this.wfd, this.msg);
  }
  powerOn() { this.send(2, 0, 0); }
  write(addr, value) { this.writes++; this.send(0, addr, value); }
  read(addr) {
    this.reads++;
    this.send(1, addr, 0);
    const b = Buffer.alloc(4);
    let got = 0;
    while (got < 4) got += fs.readSync(this.rfd, b, got, 4 - got, null);
    return b.readUInt32LE(0);
  }
  close() {
    this.closing = true;
    fs.closeSync(this.wfd);
    fs.closeSync(this.rfd);
    fs.rmSync(this.dir, { recursive: true, force: true });
  }
}

// ---------------------------------------------------------------- frames
function frame(cmd, seq, payload = new Uint8Array(0)) {
  const f = new Uint8Array(12 + payload.length);
  f.set([0xcb, 1, cmd, 0, seq & 0xff, seq >> 8, payload.length & 0xff, payload.length >> 8]);
  f.set(payload, 8);
  const c = crc32(f.subarray(0, 8 + payload.length));
  new DataView(f.buffer).setUint32(8 + payload.length, c, true);
  return f;
}

// Splits a byte stream into frames (drops garbage before a magic byte).
function parseFrames(bytes) {
  const out = [];
  let i = 0;
  while (i + 12 <= bytes.length) {
    if (bytes[i] !== 0xcb) { i++; continue; }
    const len = bytes[i + 6] | (bytes[i + 7] << 8);
    if (len > 4096) { i++; continue; }
    if (i + 12 + len > bytes.length) break;
    const f = bytes.subarray(i, i + 12 + len);
    const crc = new DataView(f.buffer, f.byteOffset).getUint32(8 + len, true);
    if (crc !== crc32(f.subarray(0, 8 + len))) { i++; continue; }
    out.push({ cmd: f[2], status: f[3], seq: f[4] | (f[5] << 8), payload: f.slice(8, 8 + len) });
    i += 12 + len;
  }
  return out;
}

// ---------------------------------------------------------------- the FPGA
// iCE40 SPI-slave configuration (Lattice TN1248) on SPI1 + CRESET_B (GPIO27),
// SS (GPIO9), CDONE (GPIO26); then the register map on SPI0, CS on GPIO1.
const PIN = { REG_CS: 1, CFG_SS: 9, CDONE: 26, CRESET: 27, FPGA_CLK: 24 };

class Fpga {
  constructor(board, expected, regmap, cdoneLow) {
    this.board = board;
    this.expected = expected; // the bitstream bytes, or null
    this.regmap = regmap;
    this.cdoneLow = cdoneLow;
    this.state = 'off';
    this.r = { configurations: 0, mismatches: 0, bytes: 0, errors: [] };
    this.live = false;
    this.tx = null;
    this.regBytesWhileDead = 0;
    this.minCsGapNs = Infinity;
    this.cutShort = 0;
    this.transactions = 0;
  }
  now() { return this.board.mcu.clock.nanos; }
  setCdone(v) { this.board.mcu.gpio[PIN.CDONE].setInputValue(v); }
  attach(mcu) {
    const pin = (n) => mcu.gpio[n];
    // fn(level, ns) on each change of a pin's output level, from an assumed
    // initial level (null: the first update counts as a change)
    const onEdge = (n, initial, fn) => {
      let last = initial;
      pin(n).addListener(() => {
        const v = pin(n).outputValue;
        if (v !== last) fn((last = v), this.now());
      });
    };
    onEdge(PIN.CRESET, null, (v, t) => {
      if (!v) {
        this.state = 'reset';
        this.tFall = t;
        this.live = false;
        this.setCdone(false);
      } else if (this.state === 'reset') {
        this.state = 'clearing';
        this.r = { configurations: this.r.configurations + 1, lowNs: t - this.tFall, ssLowAtRise: !pin(PIN.CFG_SS).outputValue,
          preClocks: 0, bytes: 0, mismatches: 0, trailing: 0, afterCdone: 0, waitUs: null, errors: [] };
        this.tRise = t;
      }
    });
    // When the firmware reads CDONE (SIO GPIO_IN), in clocks after the bitstream.
    const sioRead = mcu.sio.readUint32.bind(mcu.sio);
    mcu.sio.readUint32 = (offset) => {
      const v = sioRead(offset);
      const r = this.r;
      if (offset === 4 && r.bytes && r.cdoneReadAfter === undefined && (this.state === 'done' || this.cdoneLow)) {
        r.cdoneReadAfter = r.trailing + r.afterCdone;
      }
      return v;
    };
    mcu.spi[1].onTransmit = (b) => {
      this.cfgByte(b, !pin(PIN.CFG_SS).outputValue);
      mcu.spi[1].completeTransmit(0xff);
    };
    let cs = true;
    onEdge(PIN.REG_CS, true, (v, t) => {
      cs = v;
      if (!v) {
        if (this.csHighAt !== undefined) this.minCsGapNs = Math.min(this.minCsGapNs, t - this.csHighAt);
        this.tx = { bytes: [], value: 0 };
      } else {
        this.csHighAt = t;
        this.endTransaction();
      }
    });
    mcu.spi[0].onTransmit = (b) => mcu.spi[0].completeTransmit(this.regByte(b, !cs));
  }
  cfgByte(b, ssLow) {
    const r = this.r;
    if (this.state === 'clearing' || this.state === 'loading') {
      if (ssLow) {
        if (this.state === 'clearing') {
          r.waitUs = (this.now() - this.tRise) / 1000;
          this.state = 'loading';
        }
        if (r.trailing) r.errors.push('bitstream bytes after the trailing clocks');
        if (!this.expected || r.bytes >= this.expected.length || this.expected[r.bytes] !== b) r.mismatches++;
        r.bytes++;
      } else if (this.state === 'clearing') {
        r.preClocks += 8;
      } else {
        r.trailing += 8;
        const complete = this.expected && r.bytes === this.expected.length && r.mismatches === 0;
        if (complete && r.trailing >= 49 && !this.cdoneLow) {
          this.state = 'done';
          this.setCdone(true);
        }
      }
    } else if (this.state === 'done') {
      r.afterCdone += 8;
      if (r.afterCdone >= 49 && !this.live) { // user I/O start after >= 49 more clocks
        this.live = true;
        this.regmap.powerOn();
      }
    }
  }
  regByte(b) {
    const t = this.tx;
    if (!t) { this.strayBytes = (this.strayBytes || 0) + 1; return 0xff; }
    if (!this.live) { this.regBytesWhileDead++; return 0xff; }
    this.spiBytes = (this.spiBytes || 0) + 1;
    t.bytes.push(b);
    const i = t.bytes.length - 1;
    if (t.bytes[0] === 0x80) {
      if (i === 2) t.value = this.regmap.read(((t.bytes[1] << 8) | t.bytes[2]) * 4);
      return i >= 4 && i < 8 ? (t.value >>> (8 * (i - 4))) & 0xff : 0;
    }
    return 0;
  }
  endTransaction() {
    const t = this.tx;
    this.tx = null;
    if (!t || !this.live || !t.bytes.length) return;
    this.transactions++;
    const by = t.bytes;
    if (by[0] === 0x00 && by.length === 7) {
      this.regmap.write(((by[1] << 8) | by[2]) * 4, (by[3] | (by[4] << 8) | (by[5] << 16) | (by[6] << 24)) >>> 0);
    } else if (!(by[0] === 0x80 && by.length === 8)) {
      this.cutShort++;
    }
  }
}

// ---------------------------------------------------------------- the USB host
const STALL = 1 << 11;
class UsbHost {
  constructor(board) {
    this.board = board;
    this.usb = board.mcu.usbCtrl;
    this.ctl = null;
    this.outArmed = new Map();
    this.configured = false;
    this.address = 0;
    this.link = 'bulk';
    this.queue = [];
    this.queued = 0;
    this.sink = () => {};
    this.inBytes = 0;
    this.holdIn = false;
    this.heldIn = [];
    this.droppedIn = 0;
    this.badReports = 0;
    const usb = this.usb;
    usb.onUSBEnabled = () => usb.resetDevice();
    usb.onResetReceived = () => { this.resets = (this.resets || 0) + 1; this.onReset?.(); };
    usb.onEndpointRead = (ep, size) => this.endpointRead(ep, size);
    usb.onEndpointWrite = (ep, buf) => this.endpointWrite(ep, buf);
    this.aborts = [];
    const write = usb.writeUint32.bind(usb);
    usb.writeUint32 = (offset, value) => { // EP_ABORT: the device taking a packet back
      if (offset === 0x60 && value) this.aborts.push({ bits: value, t: this.now() });
      write(offset, value);
    };
    const ready = usb.indicateBufferReady.bind(usb);
    usb.indicateBufferReady = (ep, out) => { // a host that stopped reading never completes IN packets
      if (!out && ep !== 0 && this.holdIn) this.heldIn.push(ep);
      else ready(ep, out);
    };
  }
  now() { return this.board.mcu.clock.nanos; }
  dpram(off) { return this.board.mcu.usbDPRAMView.getUint32(off, true); }

  // One control transfer: resolves { stall, data }.
  control(bm, req, wValue, wIndex, wLength) {
    if (this.ctl) return Promise.reject(new Error('control transfer already pending'));
    return new Promise((resolve, reject) => {
      this.ctl = { dirIn: !!(bm & 0x80), wLength, data: [], resolve, reject, t0: this.now(), setup: [bm, req, wValue, wIndex, wLength] };
      this.usb.epStallArm = 0; // the controller clears it on SETUP
      this.usb.sendSetupPacket(new Uint8Array([bm, req, wValue & 0xff, wValue >> 8, wIndex & 0xff, wIndex >> 8,
        wLength & 0xff, wLength >> 8]));
    });
  }
  finishCtl(result) {
    const c = this.ctl;
    this.ctl = null;
    c.resolve(result);
  }
  // Called between slices: STALL and timeout of endpoint 0.
  poll() {
    const c = this.ctl;
    if (!c) return;
    if (this.usb.epStallArm && (this.dpram(0x80) & STALL || this.dpram(0x84) & STALL)) {
      this.finishCtl({ stall: true, data: new Uint8Array(c.data) });
    } else if (this.now() - c.t0 > 100e6) {
      this.ctl = null;
      c.reject(new Error(`no answer to setup ${JSON.stringify(c.setup)} within 100 ms`));
    }
  }
  endpointRead(ep, size) {
    if (ep === 0) { // status stage of a control IN transfer (or a stray OUT arm)
      const c = this.ctl;
      if (c && c.dirIn && c.wLength && !c.status) {
        // the data stage's last IN packet reaches the host 10 us after the
        // device armed it (rp2040js): collect it before finishing
        c.status = true;
        this.usb.endpointReadDone(0, new Uint8Array(0));
        const alarm = this.board.mcu.clock.createAlarm(() => {
          if (this.ctl === c) this.finishCtl({ stall: false, data: new Uint8Array(c.data) });
        });
        alarm.schedule(30000);
      }
      return;
    }
    this.outArmed.set(ep, size);
    this.pump();
  }
  endpointWrite(ep, buf) {
    if (ep === 0) {
      const c = this.ctl;
      if (!c) return;
      if (c.dirIn && c.wLength) {
        c.data.push(...buf);
        if (c.data.length > c.wLength) c.overrun = true;
      } else if (buf.length === 0) {
        this.finishCtl({ stall: false, data: new Uint8Array(0) });
      }
      return;
    }
    if (this.holdIn) { this.droppedIn += buf.length; return; }
    if (ep === 1 && this.link === 'bulk') {
      this.inBytes += buf.length;
      this.sink(buf);
    } else if (ep === 2 && this.link === 'hid') {
      const n = buf[0];
      if (buf.length !== 64 || n < 1 || n > 63) { this.badReports++; return; }
      this.inBytes += n;
      this.sink(buf.subarray(1, 1 + n));
    } else {
      this.strayIn = (this.strayIn || 0) + 1;
    }
  }
  send(bytes) {
    if (!bytes.length) return;
    this.queue.push(Uint8Array.from(bytes));
    this.queued += bytes.length;
    this.pump();
  }
  clearQueue() { this.queue = []; this.queued = 0; }
  take(n) {
    const out = new Uint8Array(Math.min(n, this.queued));
    let k = 0;
    while (k < out.length) {
      const q = this.queue[0];
      const m = Math.min(q.length, out.length - k);
      out.set(q.subarray(0, m), k);
      k += m;
      if (m === q.length) this.queue.shift();
      else this.queue[0] = q.subarray(m);
    }
    this.queued -= out.length;
    return out;
  }
  pump() {
    if (!this.configured || !this.queued) return;
    const ep = this.link === 'bulk' ? 1 : 2;
    const size = this.outArmed.get(ep);
    if (!size) return;
    this.outArmed.set(ep, 0);
    if (this.link === 'bulk') {
      this.usb.endpointReadDone(ep, this.take(64));
    } else {
      const d = this.take(63);
      const r = new Uint8Array(64);
      r[0] = d.length;
      r.set(d, 1);
      this.usb.endpointReadDone(ep, r);
    }
  }
  // Raw OUT packet on an endpoint, for the abuse cases (bypasses the queue).
  rawOut(ep, data) {
    if (!this.outArmed.get(ep)) return false;
    this.outArmed.set(ep, 0);
    this.usb.endpointReadDone(ep, data);
    return true;
  }
}

// ---------------------------------------------------------------- the board
class Board {
  constructor(opts, image, bitstream, regmap) {
    this.opts = opts;
    this.image = image;
    this.bitstream = bitstream;
    this.regmap = regmap;
    this.warnings = [];
    this.instructions = 0;
    this.boots = 0;
  }
  boot() {
    const mcu = new RP2040();
    const warnings = this.warnings;
    mcu.logger = {
      debug() {}, info() {},
      warn(c, m) { if (warnings.length < 50) warnings.push(`[${c}] ${m}`); },
      error(c, m) { throw new Error(`[${c}] ${m}`); },
    };
    this.mcu = mcu;
    for (const p of this.image) mcu.flash.set(p.data, p.addr - FLASH);
    // The boot ROM: boot2 (256 bytes at the start of flash) must carry the
    // CRC-32 of its first 252 bytes, else the ROM does not run it.
    const b2 = mcu.flash.subarray(0, 256);
    this.boot2Crc = { want: crc32Boot2(b2.subarray(0, 252)), have: new DataView(b2.buffer, b2.byteOffset).getUint32(252, true) };
    if (this.boot2Crc.want !== this.boot2Crc.have) return false;
    mcu.sram.set(b2, BOOT2_SRAM - 0x20000000);
    mcu.core.VTOR = 0;
    mcu.core.SP = BOOT2_SRAM; // the ROM's stack ends just below boot2's copy
    mcu.core.PC = BOOT2_SRAM;
    this.fpga = new Fpga(this, this.bitstream, this.regmap, this.opts.cdoneLow);
    this.fpga.attach(mcu);
    this.host = new UsbHost(this);
    this.boots++;
    return true;
  }
  // Runs the core for up to n instructions (WFI: jumps to the next alarm).
  run(n) {
    const mcu = this.mcu;
    const { core, clock } = mcu;
    const ns = 1e9 / (mcu.clkSys || 125e6);
    for (let i = 0; i < n; i++) {
      if (core.waiting) clock.tick(clock.nanosToNextAlarm || 1000);
      else clock.tick(core.executeInstruction() * ns);
    }
    this.instructions += n;
    this.host.poll();
  }
}

// A scheduler: runs the chip in slices, yielding to node's event loop.
class Runner {
  constructor(board) { this.board = board; this.stopped = false; this.waiters = []; }
  start() {
    const slice = () => {
      if (this.stopped) return;
      try {
        this.board.run(20000);
      } catch (e) {
        process.stderr.write(`${me}: the emulated chip failed: ${e.message}\n`);
        process.exit(1);
      }
      const t = this.board.mcu.clock.nanos;
      if (process.env.CBVH_EMU_DEBUG && this.board.instructions % 1000000 === 0) {
        const b = this.board;
        process.stderr.write(`debug: ${b.instructions / 1e6} M, ${(t / 1e6).toFixed(1)} ms, pc 0x${b.mcu.core.PC.toString(16)}, ` +
          `fpga ${b.fpga.state} ${b.fpga.r.bytes}, resets ${b.host.resets || 0}, ctl ${JSON.stringify(b.host.ctl?.setup)}\n`);
      }
      this.waiters = this.waiters.filter((w) => {
        if (w.cond()) { w.resolve(); return false; }
        if (t > w.deadline) { w.reject(new Error(`timed out (${w.what})`)); return false; }
        return true;
      });
      setImmediate(slice);
    };
    setImmediate(slice);
  }
  // Resolves when cond() holds, checked between slices; simulated-time limit.
  until(cond, what, simMs = 2000) {
    return new Promise((resolve, reject) => {
      this.waiters.push({ cond, resolve, reject, what, deadline: this.board.mcu.clock.nanos + simMs * 1e6 });
    });
  }
  sleep(simMs) {
    const t = this.board.mcu.clock.nanos + simMs * 1e6;
    return this.until(() => this.board.mcu.clock.nanos >= t, 'sleep', simMs + 1);
  }
}

// ---------------------------------------------------------------- enumeration
function descriptors(cfg) {
  const out = [];
  for (let i = 0; i + 2 <= cfg.length && cfg[i] >= 2; i += cfg[i]) out.push(cfg.subarray(i, i + cfg[i]));
  return out;
}

function stringOf(d) {
  let s = '';
  for (let i = 2; i + 1 < d.length; i += 2) s += String.fromCharCode(d[i] | (d[i + 1] << 8));
  return s;
}

// As Linux does it: device descriptor (64), SET_ADDRESS, device (18), config
// (9, then all), strings, SET_CONFIGURATION(1); HID: SET_IDLE, report descriptor.
async function enumerate(board, report, expect) {
  const h = board.host;
  const c = (...a) => h.control(...a);
  h.configured = false;
  let r = await c(0x80, 6, 0x0100, 0, 64);
  const dev = r.data;
  await c(0x00, 5, 9, 0, 0);
  h.address = board.mcu.usbCtrl.addrEndp & 0x7f;
  r = await c(0x80, 6, 0x0100, 0, 18);
  const dev18 = r.data;
  r = await c(0x80, 6, 0x0200, 0, 9);
  const total = r.data.length >= 4 ? r.data[2] | (r.data[3] << 8) : 0;
  r = await c(0x80, 6, 0x0200, 0, total);
  const cfg = r.data;
  const langs = (await c(0x80, 6, 0x0300, 0, 255)).data;
  const str = {};
  for (const i of [1, 2, 3]) str[i] = stringOf((await c(0x80, 6, 0x0300 | i, 0x0409, 255)).data);
  r = await c(0x00, 9, 1, 0, 0);
  const setConfigOk = !r.stall;
  h.configured = setConfigOk;
  const idle = await c(0x21, 10, 0, 1, 0);
  const rep = (await c(0x81, 6, 0x2200, 1, 255)).data;
  if (!report) return;
  const dv = new DataView(dev18.buffer);
  check(dev.length === 18 && dev18.length === 18 && dev[0] === 18 && dev[1] === 1, 'device descriptor: 18 bytes');
  check(dv.getUint16(2, true) === 0x0200 && dev18[7] === 64, 'device descriptor: USB 2.0, endpoint 0 of 64 bytes');
  check(dv.getUint16(8, true) === expect.vid && dv.getUint16(10, true) === expect.pid,
    `device descriptor: VID:PID ${dv.getUint16(8, true).toString(16)}:${dv.getUint16(10, true).toString(16)} as docs/protocol.md`,
    `expected ${expect.vid.toString(16)}:${expect.pid.toString(16)}`);
  check(h.address === 9, `SET_ADDRESS: the device took address ${h.address}`);
  check(langs.length === 4 && langs[2] === 0x09 && langs[3] === 0x04, 'string 0: language en-US');
  check(str[2] === expect.product, `product string '${str[2]}' as docs/protocol.md`, `expected '${expect.product}'`);
  check(str[1].length > 0 && str[3].length > 0, `manufacturer '${str[1]}', serial '${str[3]}'`);
  const ds = descriptors(cfg);
  check(cfg.length === total && cfg[1] === 2 && cfg[4] === 2, `configuration: ${total} bytes, 2 interfaces`);
  const ifaces = [];
  for (const d of ds) {
    if (d[1] === 4) ifaces.push({ num: d[2], cls: d[5], eps: [], hid: null });
    else if (d[1] === 5 && ifaces.length) ifaces.at(-1).eps.push({ addr: d[2], type: d[3] & 3, mps: d[4] | (d[5] << 8) });
    else if (d[1] === 0x21 && ifaces.length) ifaces.at(-1).hid = d;
  }
  const i0 = ifaces.find((i) => i.num === 0);
  const i1 = ifaces.find((i) => i.num === 1);
  check(i0 && i0.cls === 0xff && i0.eps.some((e) => e.addr === 0x01 && e.type === 2) &&
    i0.eps.some((e) => e.addr === 0x81 && e.type === 2), 'interface 0: vendor class, bulk OUT 0x01 / IN 0x81 (docs/protocol.md)');
  check(i1 && i1.cls === 3 && i1.hid && i1.eps.length === 2 &&
    i1.eps.every((e) => e.type === 3 && e.mps === 64), 'interface 1: HID, interrupt IN/OUT of 64 bytes');
  check(setConfigOk && !idle.stall, 'SET_CONFIGURATION(1), SET_IDLE accepted');
  const hidLen = i1 && i1.hid ? i1.hid[7] | (i1.hid[8] << 8) : -1;
  // report descriptor: report count 64 for input and output, no report ID item (0x85)
  const items = [];
  for (let i = 0; i < rep.length;) {
    const size = [0, 1, 2, 4][rep[i] & 3];
    items.push({ tag: rep[i] & 0xfc, value: rep[i + 1] | 0 });
    i += 1 + size;
  }
  check(rep.length === hidLen && !items.some((t) => t.tag === 0x84) &&
    items.filter((t) => t.tag === 0x94 && t.value === 64).length === 2 &&
    items.some((t) => t.tag === 0x80) && items.some((t) => t.tag === 0x90),
  `HID report descriptor (${rep.length} bytes): 64-byte input and output reports, no report IDs (docs/protocol.md)`);
}

// What docs/protocol.md says the device is.
function protocolFacts(file) {
  const f = { vid: VID, pid: PID, product: 'cbvh board' };
  if (!file) return f;
  const t = fs.readFileSync(file, 'utf8');
  const m = t.match(/VID:PID \*\*([0-9A-Fa-f]{4}):([0-9A-Fa-f]{4})\*\*/);
  const p = t.match(/product string `([^`]+)`/);
  if (!m || !p) throw new Error(`${file}: no 'VID:PID **XXXX:XXXX**' or 'product string \`...\`' to check against`);
  return { vid: parseInt(m[1], 16), pid: parseInt(m[2], 16), product: p[1] };
}

// ---------------------------------------------------------------- exchanges with the firmware
async function transact(runner, board, link, req, simMs = 2000) {
  const h = board.host;
  h.link = link;
  const got = [];
  h.sink = (b) => got.push(...b);
  const want = req[4] | (req[5] << 8);
  h.send(req);
  await runner.until(() => parseFrames(Uint8Array.from(got)).some((f) => f.seq === want), `reply to seq ${want}`, simMs);
  return parseFrames(Uint8Array.from(got)).find((f) => f.seq === want);
}

async function identify(runner, board, link, seq) {
  const f = await transact(runner, board, link, frame(1, seq));
  const p = f.payload;
  const name = Buffer.from(p.subarray(20, 36)).toString('latin1').replace(/\0.*$/, '');
  const dv = new DataView(p.buffer, p.byteOffset);
  return { f, name, units: dv.getUint32(8, true), regId: dv.getUint32(16, true), maxPayload: dv.getUint16(12, true) };
}

// ---------------------------------------------------------------- check mode
async function checkMode(opts, board, runner) {
  const expect = protocolFacts(opts.protocol);
  const h = board.host;
  const mcu = board.mcu;
  await runner.until(() => h.resets > 0, 'the device acknowledging the first bus reset', 5000);
  await enumerate(board, true, expect);
  check(mcu.core.VTOR === 0x10000100, `boot2 entered the image through its vector table (VTOR 0x${mcu.core.VTOR.toString(16)})`);
  check(mcu.clkSys === 125e6, `clk_sys ${mcu.clkSys / 1e6} MHz from PLL_SYS`);
  check(mcu.pllUsb.frequency === 48e6 && ((mcu.clocks.usbCtrl >> 11) & 1) === 1,
    `clk_usb ${mcu.pllUsb.frequency / 1e6} MHz from PLL_USB`);
  check(((mcu.clocks.gpout2Ctrl >> 5) & 0xf) === 5 && ((mcu.clocks.gpout2Ctrl >> 11) & 1) === 1 &&
    mcu.gpio[PIN.FPGA_CLK].functionSelect === 8, 'FPGA clock: XOSC 12 MHz on GPIO24 (clk_gpout2)');
  check(mcu.spi[0].spiMode === 0 && mcu.spi[0].clockFrequency <= 1.5e6,
    `register-map SPI0: mode 0, SCK ${(mcu.spi[0].clockFrequency / 1e6).toFixed(3)} MHz (at most 1.5)`);

  const r = board.fpga.r;
  if (opts.noBitstream) {
    check(r.configurations === 0, 'no bitstream in flash: CRESET_B never pulsed, the FPGA left alone');
  } else {
    check(r.configurations === 1, `FPGA configured once (${r.configurations})`);
    check(r.lowNs >= 200, `CRESET_B low for ${(r.lowNs / 1000).toFixed(1)} us (at least 200 ns)`);
    check(r.ssLowAtRise, 'SS low when CRESET_B rose: SPI slave mode');
    check(r.waitUs >= 1200, `first bitstream byte ${r.waitUs?.toFixed(0)} us after CRESET_B rose (at least 1200)`);
    check(r.preClocks >= 8, `${r.preClocks} dummy clocks with SS high before the bitstream`);
    check(r.bytes === board.bitstream.length && r.mismatches === 0,
      `bitstream: ${r.bytes} bytes sent, ${board.bitstream.length} expected, ${r.mismatches} differ`);
    check(r.cdoneReadAfter >= 49, `CDONE read ${r.cdoneReadAfter} clocks after the last bitstream byte (at least 49)`);
    if (!opts.cdoneLow) {
      const more = r.trailing + r.afterCdone - r.cdoneReadAfter;
      check(more >= 49, `${more} more clocks after CDONE was high, to start the user I/O (at least 49)`);
    } else {
      check(r.trailing + r.afterCdone === r.cdoneReadAfter, 'CDONE low: no clocks sent after the failed check');
    }
  }
  const want = opts.noBitstream ? 'cbvh-no-bits' : opts.cdoneLow ? 'cbvh-cdone-low' : 'cbvh-rp2040';
  for (const link of ['bulk', 'hid']) {
    const id = await identify(runner, board, link, link === 'bulk' ? 1 : 2);
    check(id.f.status === 0 && id.name === want, `IDENTIFY over ${link}: board '${id.name}'`, `expected '${want}'`);
    if (want === 'cbvh-rp2040') {
      check(id.regId === 0x48564243 && id.units !== 0 && id.maxPayload === 4096,
        `IDENTIFY over ${link}: register map 'CBVH', units 0x${id.units.toString(16)}, max payload ${id.maxPayload}`);
    } else {
      check(id.regId === 0 && id.units === 0, `IDENTIFY over ${link}: no units, no register map (the FPGA is not up)`);
      const run = new Uint8Array(12 + 4);
      run.set([1, 6, 0xe2, 0xff, 0, 1, 1, 0, 1, 0, 0, 0]);
      const f = await transact(runner, board, link, frame(3, 20, run));
      check(f.status === 9, `RUN refused with error ${f.status} (9: unit not present)`);
    }
  }
  check(board.fpga.regBytesWhileDead === 0, `no register access while the FPGA was not configured (${board.fpga.regBytesWhileDead} bytes)`);
  if (want === 'cbvh-rp2040') {
    const payload = new Uint8Array(4096).map((_, i) => (i * 31 + 7) & 0xff);
    for (const link of ['bulk', 'hid']) {
      const f = await transact(runner, board, link, frame(4, 30, payload), 5000);
      check(f.status === 0 && Buffer.compare(Buffer.from(f.payload), Buffer.from(payload)) === 0,
        `LOOPBACK of 4096 bytes over ${link}`);
    }
    // RP2040 time per vector: a RUN of 100 scale_estimate vectors (N 6, min
    // scale -30), its shape read from the register map first
    board.regmap.write(0x00c, 6 | ((-30 & 0xffff) << 8));
    board.regmap.write(0x010, 1);
    const shape = board.regmap.read(0x014);
    const nIn = shape & 0xff;
    const nOut = (shape >> 8) & 0xff;
    const count = 100;
    const run = new Uint8Array(12 + 4 * nIn * count);
    run.set([1, 6, 0xe2, 0xff, 0, nIn, nOut, 0, count, 0, 0, 0]);
    for (let i = 12; i < run.length; i += 4) run[i] = i & 0x7f;
    const spi0 = board.fpga.spiBytes;
    const t0 = board.mcu.clock.nanos;
    const f = await transact(runner, board, 'bulk', frame(3, 40, run), 5000);
    const us = (board.mcu.clock.nanos - t0) / 1000 / count;
    const spiPer = (board.fpga.spiBytes - spi0) / count;
    check(f.status === 0 && f.payload.length === 4 + 4 * nOut * count,
      `RUN of ${count} scale_estimate vectors over bulk: ${us.toFixed(0)} us of RP2040 time per vector, ` +
      `${spiPer.toFixed(0)} SPI bytes per vector (emulated cycles; no SPI or USB wire time)`);
    check(board.fpga.minCsGapNs >= 333, `register-map CS high at least ${(board.fpga.minCsGapNs / 1000).toFixed(2)} us between transactions (4 FPGA clocks: 0.33 us)`);
    check(board.fpga.cutShort === 0, `${board.fpga.transactions} register transactions, none cut short`);
  }
  if (opts.usbAbuse) await abuse(board, runner, expect);
  check(board.warnings.length === 0, `no access to an unmodelled register (${board.warnings.length})`, board.warnings.slice(0, 3).join('; '));
}

// Malformed setups, random setups, a flood, hosts that vanish: the device
// must keep answering (USB side never hangs or crashes it).
async function abuse(board, runner, expect) {
  const h = board.host;
  const c = (...a) => h.control(...a);
  const stalls = async (what, ...a) => check((await c(...a)).stall, `STALL: ${what}`);
  await stalls('unknown standard request', 0x80, 0xff, 0, 0, 64);
  await stalls('vendor request', 0xc0, 1, 0, 0, 64);
  await stalls('SET_DESCRIPTOR with a data stage', 0x00, 7, 0x0100, 0, 18);
  await stalls('SET_ADDRESS 200', 0x00, 5, 200, 0, 0);
  await stalls('SET_CONFIGURATION 2', 0x00, 9, 2, 0, 0);
  await stalls('device qualifier (full-speed only)', 0x80, 6, 0x0600, 0, 10);
  await stalls('string index 9', 0x80, 6, 0x0309, 0x0409, 255);
  await stalls('GET_STATUS of endpoint 0x85', 0x82, 0, 0, 0x85, 2);
  await stalls('interface 7', 0x81, 0, 0, 7, 2);
  await stalls('GET_REPORT', 0xa1, 1, 0x0100, 1, 64);
  let r = await c(0x80, 6, 0x0100, 0, 18);
  check(!r.stall && r.data.length === 18 && r.data[8] === (expect.vid & 0xff), 'after the malformed setups: device descriptor intact');
  // halt and clear the bulk IN endpoint: GET_STATUS follows it
  await c(0x02, 3, 0, 0x81, 0);
  const halted = (await c(0x82, 0, 0, 0x81, 2)).data[0];
  await c(0x02, 1, 0, 0x81, 0);
  const cleared = (await c(0x82, 0, 0, 0x81, 2)).data[0];
  check(halted === 1 && cleared === 0, 'SET_FEATURE/CLEAR_FEATURE(ENDPOINT_HALT) on 0x81, seen by GET_STATUS');

  // random setup packets, some abandoned mid-transfer by the host
  let seed = 12345;
  const rnd = () => (seed = (seed * 1103515245 + 12345) >>> 0) >>> 16;
  let answered = 0;
  for (let i = 0; i < 150; i++) {
    const s = [rnd() & 0xff, rnd() & 0xff, rnd() & 0xffff, rnd() & 0xffff, rnd() & 0x1ff];
    if (i % 2) s[0] &= 0x83;
    if (i % 3) s[1] &= 0x0f;
    if (s[1] === 5 || (s[1] === 9 && s[0] === 0)) s[1] = 0; // keep the address and configuration
    if (s[0] === 0x02 && (s[1] === 1 || s[1] === 3)) s[1] = 0; // and the endpoints' halt state
    try {
      r = await c(...s);
      answered++;
    } catch (e) {
      check(false, `random setup ${JSON.stringify(s)}: ${e.message}`);
      return;
    }
  }
  check(answered === 150, `150 random setup packets answered (data, status or STALL)`);
  const id0 = await identify(runner, board, 'bulk', 100);
  check(id0.f.status === 0, 'after the random setups: IDENTIFY answered');

  // oversized: 64 KiB of junk with a frame header claiming 65535 bytes
  const junk = new Uint8Array(65536).map((_, i) => (i * 13 + 1) & 0xff);
  junk.set([0xcb, 1, 4, 0, 1, 0, 0xff, 0xff]);
  const t0 = board.mcu.clock.nanos;
  h.link = 'bulk';
  h.sink = () => {};
  h.send(junk);
  await runner.until(() => h.queued === 0, 'the device taking 64 KiB', 5000);
  await runner.sleep(30);
  const id1 = await identify(runner, board, 'bulk', 101);
  check(id1.f.status === 0, `after a 64 KiB flood (${((board.mcu.clock.nanos - t0) / 1e6).toFixed(0)} ms simulated): IDENTIFY answered`);

  // a host that sends half a frame and vanishes: the 20 ms inter-byte timeout
  const got = [];
  h.sink = (b) => got.push(...b);
  const half = frame(4, 102, new Uint8Array(1000)).subarray(0, 500);
  h.send(half);
  const t2 = board.mcu.clock.nanos;
  await runner.until(() => parseFrames(Uint8Array.from(got)).some((f) => f.status === 5), 'timeout error reply', 200);
  check(true, `half a frame then silence: timeout error reply (5) after ${((board.mcu.clock.nanos - t2) / 1e6).toFixed(0)} ms`);
  const id2 = await identify(runner, board, 'bulk', 103);
  check(id2.f.status === 0, 'after the cut frame: IDENTIFY answered');

  // a host that stops reading in the middle of a 4 KiB reply
  h.holdIn = true;
  const t1 = board.mcu.clock.nanos;
  const aborts = h.aborts.length;
  h.send(frame(4, 104, new Uint8Array(4096)));
  await runner.until(() => h.aborts.length > aborts, 'the device giving up', 2000);
  const gaveUp = h.aborts.at(-1);
  h.holdIn = false;
  h.heldIn = [];
  check(gaveUp.bits === 1 << 2 && gaveUp.t - t1 < 400e6,
    `host stopped reading mid-reply: the device took back its IN packet (EP_ABORT 0x${gaveUp.bits.toString(16)}) after ${((gaveUp.t - t1) / 1e6).toFixed(0)} ms`);
  const id3 = await identify(runner, board, 'bulk', 105);
  check(id3.f.status === 0, 'a new host after that: IDENTIFY answered');

  // a bus reset in the middle of a reply, then enumeration again
  h.send(frame(4, 106, new Uint8Array(4096)));
  await runner.until(() => h.inBytes > 0, 'reply started', 200);
  h.clearQueue();
  const resets = h.resets;
  board.mcu.usbCtrl.resetDevice();
  await runner.until(() => h.resets > resets, 'bus reset', 100);
  h.configured = false;
  await enumerate(board, false, expect);
  const id4 = await identify(runner, board, 'bulk', 107);
  check(id4.f.status === 0, 'bus reset mid-reply, enumerated again: IDENTIFY answered');
}

// ---------------------------------------------------------------- serve mode
async function serveMode(opts, board, runner, regmap) {
  const expect = protocolFacts(opts.protocol);
  let client = null;
  let resetDone = false;
  let bytesOut = 0;
  const attach = () => {
    const h = board.host;
    h.link = opts.link;
    h.sink = (b) => {
      bytesOut += b.length;
      if (client) client.write(Buffer.from(b));
      if (opts.resetAfterBytes && !resetDone && bytesOut >= opts.resetAfterBytes) {
        resetDone = true;
        setImmediate(() => chipReset());
      }
    };
  };
  const bootAndEnumerate = async () => {
    await runner.until(() => board.host.resets > 0, 'first bus reset', 5000);
    await enumerate(board, false, expect);
    attach();
  };
  let ready = bootAndEnumerate();
  const chipReset = async () => {
    // The RUN pin: the chip starts over from the boot ROM (FPGA configuration
    // included); the host's link breaks like a USB disconnect.
    process.stderr.write(`${me}: resetting the chip after ${bytesOut} reply bytes\n`);
    if (client) client.destroy();
    client = null;
    board.boot();
    stats.chipResets++;
    ready = bootAndEnumerate();
    await ready;
    process.stderr.write(`${me}: chip back, enumerated\n`);
  };
  await ready;
  try { fs.unlinkSync(opts.listen); } catch { /* none */ }
  const server = net.createServer((sock) => {
    if (client) { sock.destroy(); return; } // one host at a time, as a USB device
    client = sock;
    stats.connections++;
    board.host.clearQueue();
    sock.on('data', async (d) => {
      if (sock !== client) return;
      stats.bytesIn += d.length;
      await ready;
      if (sock === client) board.host.send(d);
    });
    sock.on('close', () => { if (client === sock) { client = null; board.host.clearQueue(); } });
    sock.on('error', () => {});
  });
  server.listen(opts.listen, () => {
    if (opts.ready) fs.writeFileSync(opts.ready, `${process.pid}\n`);
  });
  const stop = () => {
    server.close();
    try { fs.unlinkSync(opts.listen); } catch { /* gone */ }
    runner.stopped = true;
    stats.bytesOut = bytesOut;
    stats.instructions = board.instructions;
    stats.simulatedMs = board.mcu.clock.nanos / 1e6;
    stats.realMs = Date.now() - stats.started;
    stats.transactions = board.fpga.transactions;
    stats.spiBytes = board.fpga.spiBytes || 0;
    try {
      if (opts.stats) fs.writeFileSync(opts.stats, JSON.stringify(stats, null, 1) + '\n');
    } catch (e) {
      process.stderr.write(`${me}: cannot write ${opts.stats}: ${e.message}\n`);
    }
    regmap.close();
    process.exit(0);
  };
  process.on('SIGTERM', stop);
  process.on('SIGINT', stop);
}
const stats = { started: Date.now(), connections: 0, bytesIn: 0, chipResets: 0 };

// ---------------------------------------------------------------- main
async function main() {
  const opts = parseArgs(process.argv.slice(2));
  quiet = !!opts.quiet;
  let image;
  try {
    image = loadUf2(opts.uf2);
  } catch (e) {
    process.stderr.write(`${me}: ${e.message}\n`);
    process.exit(1);
  }
  if (opts.noBitstream) image = image.filter((p) => p.addr < BITSTREAM_REGION);
  if (opts.corruptBoot2) image[0].data[17] ^= 0x10;
  const bitstream = opts.bitstream ? new Uint8Array(fs.readFileSync(opts.bitstream)) : null;
  if (bitstream && !opts.noBitstream) { // the UF2's region holds exactly this bitstream
    const region = image.filter((p) => p.addr >= BITSTREAM_REGION).map((p) => p.data);
    const bytes = Buffer.concat(region);
    const ok = bytes.length >= 16 && bytes.readUInt32LE(0) === 0x42564243 && bytes.readUInt32LE(4) === bitstream.length &&
      bytes.readUInt32LE(8) === crc32(bitstream) && Buffer.compare(bytes.subarray(16, 16 + bitstream.length), Buffer.from(bitstream)) === 0;
    if (opts.mode === 'check') check(ok, `UF2 bitstream region at 0x${BITSTREAM_REGION.toString(16)}: header, CRC and ${bitstream.length} bytes`);
  }
  const regmap = new Regmap(opts.regmap);
  const board = new Board(opts, image, bitstream, regmap);
  const booted = board.boot();
  if (opts.mode === 'check') {
    const { want, have } = board.boot2Crc;
    if (opts.corruptBoot2) {
      check(!booted, `boot ROM refuses boot2 with a flipped bit (CRC 0x${have.toString(16)}, computed 0x${want.toString(16)})`);
      finish(regmap);
      return;
    }
    check(booted, `boot2 CRC 0x${have.toString(16)} matches (computed 0x${want.toString(16)})`);
    if (!booted) finish(regmap);
  } else if (!booted) {
    process.stderr.write(`${me}: boot ROM: boot2 CRC mismatch, the chip would not start\n`);
    process.exit(1);
  }
  const runner = new Runner(board);
  runner.start();
  if (opts.mode === 'serve') {
    await serveMode(opts, board, runner, regmap);
    return;
  }
  try {
    await checkMode(opts, board, runner);
  } catch (e) {
    check(false, e.message);
  }
  runner.stopped = true;
  const secs = (Date.now() - stats.started) / 1000;
  console.log(`${me}: ${(board.instructions / 1e6).toFixed(1)} M instructions, ${(board.mcu.clock.nanos / 1e6).toFixed(0)} ms simulated, ${secs.toFixed(1)} s`);
  finish(regmap);
}

function finish(regmap) {
  regmap.close();
  console.log(`${results.passed} passed, ${results.failed} failed`);
  process.exit(results.failed ? 1 : 0);
}

main();
