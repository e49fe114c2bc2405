// The C++ testbench around the Verilated system: clocks, camera replays, the CH7301C pin recorder, watches.
//
// Shared by the project's route (ctestbench.cpp, driven from Python through ctypes: sim/runners/verilator/ctestbench.py) and
// the raw reference model (raw_main.cpp, driven from a stimulus file). Both run the same event loop, so the
// design is evaluated at the same instants with the same inputs; the raw model only replaces Python's answers by
// the log of them.
//
// The model's ports come from ports.inc (generated from the Verilated header: PORT(member, "name", is_input, width)
// lines, the C++ member and the Verilog name; WIDE(...) lines for ports wider than 64 bits, left alone); the
// testbench addresses them by index. Time is in picoseconds.
//
// Event loop (Engine::run), one iteration per instant:
//   * a recorder sample point (a quarter pixel period after each pixel-clock edge) reads the pins, no eval (one
//     that falls on a clock edge is taken before the edge);
//   * otherwise every clock with an edge at that instant toggles (a camera's pins take the next sample of its
//     stream on its clock's falling edge, like a sensor that launches data on the falling edge), then one eval;
//   * after each eval that follows a rising clock edge or an input change, the watched outputs (the I2C lines, the
//     status outputs the scenario waits for) are compared with their last values: a change stops the run, so
//     Python answers at that instant and nothing polls.
// Inputs set from outside (Python, or the raw model's stimulus log) are applied after the edges of the current
// instant; the next run() evaluates them at that instant before time moves on. Every stimulus is logged with
// the number of evals done before it, which is how the raw model replays it at exactly the same point.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "Vsystem.h"
#include "verilated.h"

namespace tb {

constexpr uint64_t NEVER = UINT64_MAX;

struct Port {
    const char* name;
    void* ptr;
    uint8_t bytes;        // its storage in the model
    uint8_t width;        // its bits (a value written must fit: Verilator expects the bits above it clear)
    bool input;

    uint64_t get() const {
        switch (bytes) {
            case 1: return *static_cast<uint8_t*>(ptr);
            case 2: return *static_cast<uint16_t*>(ptr);
            case 4: return *static_cast<uint32_t*>(ptr);
            default: return *static_cast<uint64_t*>(ptr);
        }
    }
    void set(uint64_t v) const {
        switch (bytes) {
            case 1: *static_cast<uint8_t*>(ptr) = static_cast<uint8_t>(v); break;
            case 2: *static_cast<uint16_t*>(ptr) = static_cast<uint16_t>(v); break;
            case 4: *static_cast<uint32_t*>(ptr) = static_cast<uint32_t>(v); break;
            default: *static_cast<uint64_t*>(ptr) = v; break;
        }
    }
};

template <class T>
Port make_port(const char* name, T& field, bool input, int width) {
    return Port{name, &field, static_cast<uint8_t>(sizeof(T)), static_cast<uint8_t>(width), input};
}

inline std::vector<Port> bind_ports(Vsystem* top) {
    std::vector<Port> ports;
#define PORT(member, name, input, width) ports.push_back(make_port(name, top->member, input, width));
#define WIDE(member, name, input, width)  // wider than 64 bits: not bound (an input stays 0)
#include "ports.inc"
#undef WIDE
#undef PORT
    return ports;
}

// A free-running clock from its first rising edge on, with a fixed half period.
struct Clock {
    uint8_t* pin = nullptr;
    uint64_t next = NEVER;  // time of its next edge
    uint64_t half = 0;
    uint8_t level = 0;
};

// A sensor's frame period replayed on its pins: the next 10-bit word {fv, lv, d[7:0]} at every falling edge of
// its clock, from word 0 again after the last. `seen` keeps the pins at the rising edges (what the capture
// samples) from the first rising edge after the first falling edge on, for the check against the stream.
struct Camera {
    const uint16_t* words = nullptr;
    uint64_t length = 0, index = 0;
    uint8_t *data = nullptr, *lv = nullptr, *fv = nullptr;
    uint16_t* seen = nullptr;
    uint64_t seen_max = 0, seen_count = 0;
    bool running = false, driven = false;

    void falling() {
        uint16_t w = words[index];
        *data = static_cast<uint8_t>(w & 0xFF);
        *lv = (w >> 8) & 1;
        *fv = (w >> 9) & 1;
        index = index + 1 == length ? 0 : index + 1;
        driven = true;
    }
    void rising() {
        if (driven && seen_count < seen_max)
            seen[seen_count++] = static_cast<uint16_t>(*data | (*lv << 8) | (*fv << 9));
    }
};

// The CH7301C pins sampled a quarter pixel period after each pixel-clock edge, one 31-bit word per pixel clock:
// bits 0-11 the word after the rising edge, 12-23 the word after the falling edge, 24-28 {xclk_p, xclk_n, hsync,
// vsync, de} after the rising edge (bit 28 = xclk_p), 29-30 {xclk_p, xclk_n} after the falling edge.
struct Recorder {
    const Port *data = nullptr, *hsync = nullptr, *vsync = nullptr, *de = nullptr, *xclk_p = nullptr,
               *xclk_n = nullptr;
    uint32_t* out = nullptr;
    uint64_t limit = 0, count = 0;
    uint64_t next = NEVER;  // next sample point
    uint64_t half = 0;
    bool high = true;       // the next sample point follows a rising edge
    uint32_t pending = 0;

    void sample() {
        uint32_t word = static_cast<uint32_t>(data->get() & 0xFFF);
        uint32_t xclk = static_cast<uint32_t>((xclk_p->get() & 1) << 1 | (xclk_n->get() & 1));
        if (high) {
            pending = word | (xclk << 27) | static_cast<uint32_t>((hsync->get() & 1) << 26 |
                                                                   (vsync->get() & 1) << 25 | (de->get() & 1) << 24);
        } else {
            out[count++] = pending | (word << 12) | (xclk << 29);
        }
        high = !high;
        next = count < limit ? next + half : NEVER;
    }
};

// Watched outputs: run() stops after an evaluation that changed one. One-byte ports (the usual case) are compared
// without branches; wider ones through their Port.
struct Watches {
    static constexpr int MAX = 32;
    const uint8_t* byte[MAX];
    uint8_t byte_value[MAX];
    int bytes = 0;
    std::vector<std::pair<const Port*, uint64_t>> wide;

    bool empty() const { return bytes == 0 && wide.empty(); }
    void clear() {
        bytes = 0;
        wide.clear();
    }
    bool add(const Port& p) {
        if (p.bytes != 1) {
            wide.emplace_back(&p, p.get());
        } else if (bytes < MAX) {
            byte[bytes] = static_cast<const uint8_t*>(p.ptr);
            byte_value[bytes] = *byte[bytes];
            ++bytes;
        } else {
            return false;
        }
        return true;
    }
    bool changed() {
        unsigned diff = 0;
        for (int i = 0; i < bytes; ++i) diff |= *byte[i] ^ byte_value[i];
        for (const auto& w : wide) diff |= w.first->get() != w.second;
        if (!diff) return false;
        for (int i = 0; i < bytes; ++i) byte_value[i] = *byte[i];
        for (auto& w : wide) w.second = w.first->get();
        return true;
    }
};

enum Reason : int { LIMIT = 0, WATCH = 1, RECORDED = 2, EVALS = 3 };

enum Kind : uint32_t { SET = 0, CLOCK = 1, CAMERA = 2, RECORD = 3 };

// One stimulus: applied after `evals` evaluations, at time `t`. SET: port `a` = `b`. CLOCK: clock `a` starts, first
// rising edge at `b`. CAMERA: camera `a` replays its `b`-word stream from now on. RECORD: the recorder records `b`
// pixel clocks from the next rising edge of the pixel clock.
struct Stimulus {
    uint64_t evals, t;
    uint32_t kind, a;
    uint64_t b;
};

struct Engine {
    VerilatedContext context;
    Vsystem* top;
    std::vector<Port> ports;
    // sync, pix, cam_a, cam_b, mem (MIG's clk0: the DDR2 build only; a clock never started has no edges)
    static constexpr int CLOCKS = 5, PIX = 1, CAM = 2;
    Clock clocks[CLOCKS];
    Camera cameras[2];        // on the clocks cam_a, cam_b
    Recorder recorder;
    Watches watches;
    // Watched outputs are compared after evaluations with a rising clock edge or changed inputs: the design's
    // registers change on rising edges only (true unless its Verilog has negedge logic: then set this), and a
    // watched output is a register or a function of registers and inputs, not of a clock's level.
    bool watch_falling_edges = false;
    uint64_t now = 0, evals = 0, eval_stop = NEVER;
    bool dirty = true;        // inputs changed since the last eval (the first eval: time 0)
    std::vector<Stimulus> log;
    bool logging = false;

    Engine() : top(new Vsystem(&context, "system")), ports(bind_ports(top)) {}
    ~Engine() {
        top->final();
        delete top;
    }

    void note(uint32_t kind, uint32_t a, uint64_t b) {
        if (logging) log.push_back(Stimulus{evals, now, kind, a, b});
    }
    void set(int port, uint64_t value) {
        ports[port].set(value);
        dirty = true;
        note(SET, port, value);
    }
    void start_clock(int clock, uint64_t first_rise) {
        clocks[clock].next = first_rise;
        clocks[clock].level = 0;
        *clocks[clock].pin = 0;
        note(CLOCK, clock, first_rise);
    }
    void start_camera(int c) {
        cameras[c].index = 0;
        cameras[c].running = true;
        note(CAMERA, c, cameras[c].length);
    }
    void record(uint64_t pixel_clocks) {
        const Clock& pix = clocks[PIX];
        uint64_t rise = pix.level ? pix.next + pix.half : pix.next;   // the next rising edge after now
        recorder.limit = pixel_clocks;
        recorder.count = 0;
        recorder.half = pix.half;
        recorder.high = true;
        recorder.next = pixel_clocks ? rise + pix.half / 2 : NEVER;
        note(RECORD, 0, pixel_clocks);
    }

    void eval() {
        context.time(now);
        top->eval();
        ++evals;
        dirty = false;
    }

    // Run until `limit` (every instant up to and including it is done), a watch fires, the recorder is full or
    // `eval_stop` evaluations are done.
    Reason run(uint64_t limit) {
        if (dirty) {
            eval();
            if (evals == eval_stop) return EVALS;
            if (!watches.empty() && watches.changed()) return WATCH;
        }
        for (;;) {
            uint64_t t = clocks[0].next;
            for (int i = 1; i < CLOCKS; ++i)
                if (clocks[i].next < t) t = clocks[i].next;
            if (recorder.next != NEVER && recorder.next <= t) {
                if (recorder.next > limit) break;
                now = recorder.next;
                recorder.sample();
                if (recorder.count == recorder.limit) return RECORDED;
                continue;
            }
            if (t > limit || t == NEVER) break;
            now = t;
            bool rising = watch_falling_edges;
            for (int i = 0; i < CLOCKS; ++i) {
                Clock& c = clocks[i];
                if (c.next != t) continue;
                c.level ^= 1;
                *c.pin = c.level;
                c.next += c.half;
                rising |= c.level;
                if (i >= CAM && i < CAM + 2 && cameras[i - CAM].running) {
                    if (c.level) cameras[i - CAM].rising(); else cameras[i - CAM].falling();
                }
            }
            eval();
            if (evals == eval_stop) return EVALS;
            if (rising && !watches.empty() && watches.changed()) return WATCH;
        }
        now = limit;
        return LIMIT;
    }
};

}  // namespace tb
