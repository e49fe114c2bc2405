// The raw reference model: the Verilated system run from C++ alone, no Python, no cocotb, no VPI.
//
//   raw <config file>
//
// The config file (written by bench/raw_model.py) binds the clocks, cameras and recorder to the model's ports
// (indices into ports.inc) and names the files: each camera's frame-period stream (uint16 words {fv, lv, d}),
// the stimulus log of a project run (what Python's models answered, and when: testbench.h's Stimulus records)
// and the output file for the recorded CH7301C pins (uint32 words, as testbench.h's Recorder packs them).
// Prints one JSON line: evaluations, simulated time, recorded pixel clocks, the wall and CPU time of the simulation
// (from the first evaluation to the last recorded pixel clock; loading the files is not counted).
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "testbench.h"

template <class T>
static std::vector<T> read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw std::runtime_error("cannot read " + path);
    std::vector<T> data(static_cast<size_t>(in.tellg()) / sizeof(T));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size() * sizeof(T)));
    return data;
}

static void apply(tb::Engine& e, const tb::Stimulus& s) {
    e.now = s.t;
    switch (s.kind) {
        case tb::SET: e.set(static_cast<int>(s.a), s.b); break;
        case tb::CLOCK: e.start_clock(static_cast<int>(s.a), s.b); break;
        case tb::CAMERA: e.start_camera(static_cast<int>(s.a)); break;
        case tb::RECORD: e.record(s.b); break;
        default: throw std::runtime_error("unknown stimulus kind " + std::to_string(s.kind));
    }
}

struct Raw {
    tb::Engine e;
    std::vector<uint16_t> words[2];
    std::vector<uint32_t> recording;
    std::vector<tb::Stimulus> stimulus;
    std::string output;
};

static void bind_camera(Raw& raw, std::istringstream& f) {
    int c, data, lv, fv;
    std::string path;
    f >> c >> data >> lv >> fv >> path;
    raw.words[c] = read_file<uint16_t>(path);
    tb::Camera& cam = raw.e.cameras[c];
    cam.data = static_cast<uint8_t*>(raw.e.ports[data].ptr);
    cam.lv = static_cast<uint8_t*>(raw.e.ports[lv].ptr);
    cam.fv = static_cast<uint8_t*>(raw.e.ports[fv].ptr);
    cam.words = raw.words[c].data();
    cam.length = raw.words[c].size();
}

static void bind_recorder(Raw& raw, std::istringstream& f) {
    int p[6];
    uint64_t capacity;
    for (int& i : p) f >> i;
    f >> capacity;
    raw.recording.assign(capacity, 0);
    tb::Recorder& r = raw.e.recorder;
    const std::vector<tb::Port>& ports = raw.e.ports;
    r.data = &ports[p[0]], r.hsync = &ports[p[1]], r.vsync = &ports[p[2]];
    r.de = &ports[p[3]], r.xclk_p = &ports[p[4]], r.xclk_n = &ports[p[5]];
    r.out = raw.recording.data();
}

static void configure(Raw& raw, const char* path) {
    std::ifstream config(path);
    if (!config) throw std::runtime_error(std::string("cannot read ") + path);
    std::string line, key;
    while (std::getline(config, line)) {
        std::istringstream f(line);
        f >> key;
        if (key == "clock") {
            int i, port;
            uint64_t half;
            f >> i >> port >> half;
            raw.e.clocks[i].pin = static_cast<uint8_t*>(raw.e.ports[port].ptr);
            raw.e.clocks[i].half = half;
        } else if (key == "camera") {
            bind_camera(raw, f);
        } else if (key == "recorder") {
            bind_recorder(raw, f);
        } else if (key == "stimulus") {
            std::string file;
            f >> file;
            raw.stimulus = read_file<tb::Stimulus>(file);
        } else if (key == "output") {
            f >> raw.output;
        } else {
            throw std::runtime_error("unknown config line: " + line);
        }
    }
}

int main(int argc, char** argv) try {
    if (argc != 2) {
        std::cerr << "usage: " << argv[0] << " CONFIG\n";
        return 2;
    }
    Raw raw;
    configure(raw, argv[1]);
    tb::Engine& e = raw.e;
    auto start = std::chrono::steady_clock::now();
    std::clock_t cpu_start = std::clock();
    for (const tb::Stimulus& s : raw.stimulus) {
        if (s.kind == tb::RECORD && s.b > raw.recording.size()) throw std::runtime_error("recorder too small");
        if (s.evals > e.evals) {
            e.eval_stop = s.evals;
            if (e.run(tb::NEVER) != tb::EVALS) throw std::runtime_error("the run ended before the stimulus log");
        }
        apply(e, s);
    }
    e.eval_stop = tb::NEVER;
    tb::Reason end = e.run(tb::NEVER);
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    std::ofstream out(raw.output, std::ios::binary);
    out.write(reinterpret_cast<const char*>(raw.recording.data()),
              static_cast<std::streamsize>(e.recorder.count * sizeof(uint32_t)));
    std::cout << "{\"evals\": " << e.evals << ", \"t_end_ps\": " << e.now << ", \"recorded\": " << e.recorder.count
              << ", \"complete\": " << (end == tb::RECORDED ? "true" : "false") << ", \"wall_s\": " << wall
              << ", \"cpu_s\": " << cpu << "}" << std::endl;
    return end == tb::RECORDED ? 0 : 1;
} catch (const std::exception& exc) {
    std::cerr << argv[0] << ": " << exc.what() << "\n";
    return 1;
}
