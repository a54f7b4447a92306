// rl_codec: drives the RoverLink C++ codec from a pipe, so tests/firmware/native/test_native.py can hold it
// against the Python codec. Test-only; not part of the Arduino library.
//
// Reads one command per line on stdin and writes exactly one answer line per command on stdout
// (flushed after every line). Tokens are separated by single or repeated spaces.
//
//   D <hex>    Decode with a fresh roverlink::FrameDecoder, pushing the bytes one at a time.
//   DS <hex>   Decode with the streaming decoder, which keeps its state (a partial chunk, the
//              over-long skip, the counters) from one DS line to the next.
//   R          Replace the streaming decoder by a fresh one (state and counters).   -> OK
//      Both decode commands answer
//              EVENTS <item> <item> ... STATS frames_ok=N crc_errors=N cobs_errors=N ...
//                     (the decoder's counters: print_fields of proto::DecoderCounters)
//      with one item per push() result other than NONE, in order:
//              F:<NAME>:<seq>:<fields>   a good frame whose payload unpack() accepts; <fields> is
//                                        print_fields() without the leading NAME, its separating
//                                        spaces replaced by ';' ("a=1;b=0x3F800000;c=1,2;d=6869"),
//                                        empty for a message without fields ("F:DISARM:7:")
//              E:<kind>                  kind: cobs, overlong, length, unknown_id, crc, or value
//                                        (the decoder returned FRAME but unpack() rejected the
//                                        payload). Names, values and seq contain no ':', ';' or
//                                        space, so every item splits unambiguously.
//      STATS are the decoder's own counters; after a value error the tool calls reject_payload(),
//      as the firmware does, so they match the Python decoder's.
//   E <NAME> <seq> <field>=<value> ...
//              Builds the message (fields not given are zero) with reflect::set_field and encodes
//              it with roverlink::encode_message.                                 -> FRAME <hex>
//              Values must be in the print_fields text form: decimal integers (enums and flags as
//              numbers), f32 as 0x%08X of the IEEE bits, fixed arrays comma-separated, char/u8
//              trailing arrays as lowercase hex. Each value is read back through print_fields and
//              must come out identical, so a typo or an out-of-type value is an ERR, not a silent
//              truncation. Spec ranges are not checked (the C++ encoder packs what it is given).
//   C <NAME> <field>=<value> ...
//              Builds the message as E does and answers its proto::check_ranges():
//                                                 -> RANGE <index of the first bad field, 255: all valid>
//   S <state> <event> <guards>
//              proto::step(state, event, g) where g.check(Guard x) is bit x of <guards>.
//                                                 -> STEP <matched 0/1> <target> <actions>
//   Q          -> BYE, then exit 0.
// A malformed command is answered with ERR <reason>, and the tool carries on.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <iostream>
#include <string>
#include <vector>

#include "codec/codec.h"
#include "generated/roverlink_reflect.h"

using namespace roverlink;

namespace {

typedef std::vector<std::string> Tokens;

Tokens split_spaces(const std::string& line) {
    Tokens out;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && line[i] == ' ') ++i;
        const size_t start = i;
        while (i < line.size() && line[i] != ' ') ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
}

// Strict unsigned decimal: digits only, no sign, no leading spaces, at most `max`.
bool parse_uint(const std::string& s, unsigned long max, unsigned long& out) {
    if (s.empty() || s.size() > 10) return false;
    unsigned long v = 0;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] < '0' || s[i] > '9') return false;
        v = v * 10u + static_cast<unsigned long>(s[i] - '0');
    }
    if (v > max) return false;
    out = v;
    return true;
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

bool parse_hex_bytes(const std::string& s, std::vector<uint8_t>& out) {
    if (s.size() % 2 != 0) return false;
    out.clear();
    out.reserve(s.size() / 2);
    for (size_t i = 0; i < s.size(); i += 2) {
        const int hi = hex_digit(s[i]);
        const int lo = hex_digit(s[i + 1]);
        if (hi < 0 || lo < 0) return false;
        out.push_back(static_cast<uint8_t>(hi << 4 | lo));
    }
    return true;
}

std::string to_hex(const uint8_t* p, size_t n) {
    static const char digits[] = "0123456789abcdef";
    std::string s;
    s.reserve(2 * n);
    for (size_t i = 0; i < n; ++i) {
        s.push_back(digits[p[i] >> 4]);
        s.push_back(digits[p[i] & 0x0F]);
    }
    return s;
}

void answer(const std::string& line) {
    fputs(line.c_str(), stdout);
    fputc('\n', stdout);
    fflush(stdout);
}

// What reflect::print_fields writes for `m`: "NAME field=value field=value".
template <class M>
std::string print_to_string(const M& m) {
    char* buf = NULL;
    size_t size = 0;
    FILE* f = open_memstream(&buf, &size);
    if (f == NULL) {
        perror("rl_codec: open_memstream");
        exit(2);
    }
    reflect::print_fields(f, m);
    fclose(f);
    std::string s(buf, size);
    free(buf);
    return s;
}

// ---------------------------------------------------------------------------------------------
// D / DS

// Unpacks a payload into whichever message with_message() hands over and renders it as an item.
struct FrameItem {
    const uint8_t* payload;
    uint8_t len;
    uint8_t seq;
    std::string item;
    bool rejected;

    template <class M>
    void operator()(M& m) {
        if (!proto::unpack(payload, len, m)) {
            item = "E:value";
            rejected = true;
            return;
        }
        const std::string text = print_to_string(m);
        const size_t space = text.find(' ');
        const std::string name = text.substr(0, space);
        std::string fields = space == std::string::npos ? std::string() : text.substr(space + 1);
        for (size_t i = 0; i < fields.size(); ++i) {
            if (fields[i] == ' ') fields[i] = ';';
        }
        char seq_text[8];
        snprintf(seq_text, sizeof seq_text, "%u", static_cast<unsigned>(seq));
        item = "F:" + name + ":" + seq_text + ":" + fields;
    }
};

const char* error_kind(FrameDecoder::Result r) {
    switch (r) {
    case FrameDecoder::ERR_COBS: return "cobs";
    case FrameDecoder::ERR_OVERLONG: return "overlong";
    case FrameDecoder::ERR_LENGTH: return "length";
    case FrameDecoder::ERR_UNKNOWN_ID: return "unknown_id";
    case FrameDecoder::ERR_CRC: return "crc";
    case FrameDecoder::NONE:
    case FrameDecoder::FRAME:
        break;
    }
    return "internal";
}

void decode(FrameDecoder& decoder, const std::string& hex) {
    std::vector<uint8_t> bytes;
    if (!parse_hex_bytes(hex, bytes)) {
        answer("ERR bad hex");
        return;
    }
    std::string out = "EVENTS";
    for (size_t i = 0; i < bytes.size(); ++i) {
        const FrameDecoder::Result r = decoder.push(bytes[i]);
        if (r == FrameDecoder::NONE) continue;
        out += ' ';
        if (r != FrameDecoder::FRAME) {
            out += "E:";
            out += error_kind(r);
            continue;
        }
        FrameItem fi = {decoder.payload(), decoder.payload_len(), decoder.seq(), std::string(), false};
        if (!reflect::with_message(decoder.msg_id(), fi)) {
            fi.item = "E:internal";  // the decoder passed an id with_message does not know
        }
        if (fi.rejected) {
            decoder.reject_payload();
        }
        out += fi.item;
    }
    out += " STATS" + print_to_string(decoder.stats());
    answer(out);
}

// ---------------------------------------------------------------------------------------------
// E

struct Encoder {
    const Tokens* tokens;  // tokens[3..] are the field=value pairs
    uint8_t seq;
    std::string result;
    bool ranges;  // C: answer check_ranges() instead of the frame

    template <class M>
    void operator()(M& m) {
        for (size_t i = 3; i < tokens->size(); ++i) {
            const std::string& t = (*tokens)[i];
            const size_t eq = t.find('=');
            if (eq == std::string::npos || eq == 0) {
                result = "ERR expected field=value, got " + t;
                return;
            }
            const std::string name = t.substr(0, eq);
            if (!reflect::set_field(m, name.c_str(), t.c_str() + eq + 1)) {
                result = "ERR cannot set " + t;
                return;
            }
        }
        // Read every given value back through print_fields: it must come out as it went in.
        const std::string printed = print_to_string(m) + " ";
        for (size_t i = 3; i < tokens->size(); ++i) {
            if (printed.find(" " + (*tokens)[i] + " ") == std::string::npos) {
                result = "ERR " + (*tokens)[i] + " does not read back: " + printed;
                return;
            }
        }
        if (ranges) {
            char text[16];
            snprintf(text, sizeof text, "RANGE %u", static_cast<unsigned>(proto::check_ranges(m)));
            result = text;
            return;
        }
        uint8_t frame[proto::MAX_FRAME];
        const size_t n = encode_message(m, seq, frame, sizeof frame);
        if (n == 0) {
            result = "ERR encode_message failed";
            return;
        }
        result = "FRAME " + to_hex(frame, n);
    }
};

void encode(const Tokens& tokens, bool ranges) {
    if (tokens.size() < 3) {
        answer("ERR usage: E <NAME> <seq> <field>=<value> ...");
        return;
    }
    const int id = reflect::id_of(tokens[1].c_str());
    if (id < 0) {
        answer("ERR unknown message " + tokens[1]);
        return;
    }
    unsigned long seq = 0;
    if (!parse_uint(tokens[2], 255, seq)) {
        answer("ERR bad seq " + tokens[2]);
        return;
    }
    Encoder enc = {&tokens, static_cast<uint8_t>(seq), std::string(), ranges};
    if (!reflect::with_message(static_cast<uint8_t>(id), enc)) {
        answer("ERR with_message does not know " + tokens[1]);
        return;
    }
    answer(enc.result);
}

// ---------------------------------------------------------------------------------------------
// S

struct MaskGuards {
    unsigned long mask;
    bool check(proto::Guard g) {
        const unsigned bit = static_cast<unsigned>(g);
        return bit < 32 && ((mask >> bit) & 1u) != 0;
    }
};

void step(const Tokens& tokens) {
    unsigned long state = 0;
    unsigned long event = 0;
    unsigned long guards = 0;
    if (tokens.size() != 4 || !parse_uint(tokens[1], 255, state) || !parse_uint(tokens[2], 255, event) ||
        !parse_uint(tokens[3], 0xFFFFFFFFul, guards)) {
        answer("ERR usage: S <state> <event> <guards>");
        return;
    }
    MaskGuards g = {guards};
    const proto::StepResult r = proto::step(static_cast<proto::SessionState>(state),
                                            static_cast<proto::SessionEvent>(event), g);
    char out[64];
    snprintf(out, sizeof out, "STEP %d %u %u", r.matched ? 1 : 0, static_cast<unsigned>(r.target),
             static_cast<unsigned>(r.actions));
    answer(out);
}

}  // namespace

int main() {
    FrameDecoder* stream = new FrameDecoder();
    std::string line;
    while (std::getline(std::cin, line)) {
        if (!line.empty() && line[line.size() - 1] == '\r') line.erase(line.size() - 1);
        const Tokens tokens = split_spaces(line);
        if (tokens.empty()) {
            answer("ERR empty command");
            continue;
        }
        const std::string& cmd = tokens[0];
        if (cmd == "D" || cmd == "DS") {
            if (tokens.size() > 2) {
                answer("ERR usage: " + cmd + " <hex>");
            } else if (cmd == "D") {
                FrameDecoder decoder;
                decode(decoder, tokens.size() == 2 ? tokens[1] : std::string());
            } else {
                decode(*stream, tokens.size() == 2 ? tokens[1] : std::string());
            }
        } else if (cmd == "R" && tokens.size() == 1) {
            delete stream;
            stream = new FrameDecoder();
            answer("OK");
        } else if (cmd == "E") {
            encode(tokens, false);
        } else if (cmd == "C") {
            // C takes no seq: the tokens are shifted so that field pairs start at tokens[3].
            Tokens shifted = tokens;
            shifted.insert(shifted.begin() + 2, "0");
            encode(shifted, true);
        } else if (cmd == "S") {
            step(tokens);
        } else if (cmd == "Q" && tokens.size() == 1) {
            answer("BYE");
            break;
        } else {
            answer("ERR unknown command " + cmd);
        }
    }
    delete stream;
    return 0;
}
