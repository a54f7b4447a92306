// RoverLink codec runtime: include this one header.
#ifndef ROVERLINK_CODEC_CODEC_H
#define ROVERLINK_CODEC_CODEC_H

#include "../generated/roverlink_protocol.h"

// Bumped whenever the contract between this runtime and the generated header changes.
#define ROVERLINK_RUNTIME_API_VERSION 4

#if !defined(ROVERLINK_GENERATED_API_VERSION) || \
    ROVERLINK_GENERATED_API_VERSION != ROVERLINK_RUNTIME_API_VERSION
#error "src/generated/roverlink_protocol.h does not match this RoverLink runtime (API version): regenerate it with `python -m protocol generate`"
#endif

// What the runtime relies on; a generator or spec change that breaks these must fail here.
static_assert(roverlink::proto::MAX_BODY == roverlink::proto::MAX_PAYLOAD + 4,
              "MAX_BODY must be id + seq + payload + crc");
static_assert(roverlink::proto::MAX_BODY < 254,
              "the encoder assumes a body fits in a single COBS block");
static_assert(roverlink::proto::MAX_FRAME == roverlink::proto::MAX_BODY + 2,
              "MAX_FRAME must be an encoded MAX_BODY (MAX_BODY + 1) plus the delimiter");

#include "../wire/cobs.h"
#include "../wire/compiler.h"
#include "../wire/crc16.h"
#include "frame_decoder.h"
#include "frame_encoder.h"

#endif  // ROVERLINK_CODEC_CODEC_H
