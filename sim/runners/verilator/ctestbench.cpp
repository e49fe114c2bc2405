// The testbench of testbench.h as a C library, for sim/runners/verilator/ctestbench.py (ctypes). Every function takes the
// engine handle that tb_new returns; ports, clocks and cameras are numbered as testbench.h numbers them.
#include "testbench.h"

using tb::Engine;

static Engine* E(void* h) { return static_cast<Engine*>(h); }

#pragma GCC visibility push(default)
extern "C" {

void* tb_new() { return new Engine(); }
void tb_free(void* h) { delete E(h); }

int tb_port_count(void* h) { return static_cast<int>(E(h)->ports.size()); }
const char* tb_port_name(void* h, int i) { return E(h)->ports[i].name; }
int tb_port_width(void* h, int i) { return E(h)->ports[i].width; }
int tb_port_is_input(void* h, int i) { return E(h)->ports[i].input; }

void tb_set(void* h, int port, uint64_t value) { E(h)->set(port, value); }
uint64_t tb_get(void* h, int port) { return E(h)->ports[port].get(); }
uint64_t tb_now(void* h) { return E(h)->now; }
uint64_t tb_evals(void* h) { return E(h)->evals; }

void tb_bind_clock(void* h, int clock, int port, uint64_t half_ps) {
    Engine* e = E(h);
    e->clocks[clock].pin = static_cast<uint8_t*>(e->ports[port].ptr);
    e->clocks[clock].half = half_ps;
}
void tb_start_clock(void* h, int clock, uint64_t first_rise_ps) { E(h)->start_clock(clock, first_rise_ps); }

void tb_bind_camera(void* h, int c, int data, int lv, int fv, const uint16_t* words, uint64_t length,
                    uint16_t* seen, uint64_t seen_max) {
    Engine* e = E(h);
    tb::Camera& cam = e->cameras[c];
    cam.data = static_cast<uint8_t*>(e->ports[data].ptr);
    cam.lv = static_cast<uint8_t*>(e->ports[lv].ptr);
    cam.fv = static_cast<uint8_t*>(e->ports[fv].ptr);
    cam.words = words;
    cam.length = length;
    cam.seen = seen;
    cam.seen_max = seen_max;
}
void tb_start_camera(void* h, int c) { E(h)->start_camera(c); }
uint64_t tb_camera_seen(void* h, int c) { return E(h)->cameras[c].seen_count; }

void tb_bind_recorder(void* h, int data, int hsync, int vsync, int de, int xclk_p, int xclk_n, uint32_t* out) {
    Engine* e = E(h);
    tb::Recorder& r = e->recorder;
    r.data = &e->ports[data];
    r.hsync = &e->ports[hsync];
    r.vsync = &e->ports[vsync];
    r.de = &e->ports[de];
    r.xclk_p = &e->ports[xclk_p];
    r.xclk_n = &e->ports[xclk_n];
    r.out = out;
}
void tb_record(void* h, uint64_t pixel_clocks) { E(h)->record(pixel_clocks); }
uint64_t tb_recorded(void* h) { return E(h)->recorder.count; }

int tb_watch(void* h, int port) { return E(h)->watches.add(E(h)->ports[port]); }
void tb_clear_watches(void* h) { E(h)->watches.clear(); }
void tb_watch_falling_edges(void* h, int on) { E(h)->watch_falling_edges = on != 0; }

int tb_run(void* h, uint64_t limit_ps) { return E(h)->run(limit_ps); }

void tb_logging(void* h, int on) { E(h)->logging = on != 0; }
uint64_t tb_log_size(void* h) { return E(h)->log.size(); }
void tb_log_copy(void* h, void* out) {
    const auto& log = E(h)->log;
    std::memcpy(out, log.data(), log.size() * sizeof(tb::Stimulus));
}
int tb_stimulus_bytes() { return sizeof(tb::Stimulus); }

}  // extern "C"
#pragma GCC visibility pop
