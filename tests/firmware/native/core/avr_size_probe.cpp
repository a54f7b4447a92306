// Compiled for AVR only by `make core-avr`: one array per type whose size (avr-nm -S) is the
// type's sizeof on the real target, where padding and pointer sizes differ from the host's.
#include <RoverLink.h>

char sizeof_FrameDecoder[sizeof(roverlink::FrameDecoder)];
char sizeof_Link[sizeof(roverlink::Link)];
char sizeof_Session[sizeof(roverlink::Session<roverlink::Firmware>)];
char sizeof_Firmware[sizeof(roverlink::Firmware)];
char sizeof_SetConfig[sizeof(roverlink::proto::SetConfig)];
