# The portable firmware core (arduino/RoverLink/src/core) built natively: its unit tests, the
# simulator library for Python (ctypes), and an avr-g++ compile of each core .cpp. Included from
# tests/firmware/native/Makefile, whose variables (ROOT, BUILD, SRC, HERE, CXX, CXXFLAGS_COMMON, SANFLAGS,
# RUNTIME_SRCS, PROTO_SRCS, ...) it uses.
#
#   make -C tests/firmware/native core-test   test_core, plain + AddressSanitizer/UBSan; last line "N passed, 0 failed"
#   make -C tests/firmware/native sim         $(BUILD)/sim/libroverlink_sim.so (tests/support/native_sim.py)
#   make -C tests/firmware/native core-avr    avr-g++ -mmcu=atmega328p each core .cpp against the Arduino core,
#                                             avr-size per object, and sizeof(Link/Session/Firmware) on AVR

CORE_DIR      := $(HERE)/core
EXAMPLES_DIR  := $(ROOT)/arduino/RoverLink/examples
CORE_SRCS     := $(sort $(wildcard $(SRC)/core/*.cpp))
NATIVE_HAL    := $(sort $(wildcard $(SRC)/hal/native/*.cpp))
CORE_HDRS     := $(wildcard $(SRC)/core/*.h) $(wildcard $(SRC)/hal/*.h) $(wildcard $(SRC)/hal/native/*.h) \
                 $(SRC)/RoverLink.h $(wildcard $(EXAMPLES_DIR)/*/robot_profile.h) $(wildcard $(CORE_DIR)/*.h)
SIM_SRCS      := $(CORE_DIR)/sim.cpp $(CORE_DIR)/profiles.cpp $(sort $(wildcard $(CORE_DIR)/profile_*.cpp))
CORE_LIB_SRCS := $(CORE_SRCS) $(NATIVE_HAL) $(RUNTIME_SRCS) $(PROTO_SRCS) $(SIM_SRCS)
CORE_INCLUDES := -I$(SRC) -I$(EXAMPLES_DIR) -I$(CORE_DIR)
CORE_DEPS     := $(CORE_LIB_SRCS) $(CORE_HDRS) $(RUNTIME_HDRS) $(PROTO_HDRS) $(CORE_DIR)/core.mk $(HERE)/Makefile

CORE_TEST_SRCS  := $(CORE_DIR)/test_core.cpp $(CORE_DIR)/sim_api.cpp $(CORE_LIB_SRCS)
CORE_PLAIN_BIN  := $(BUILD)/plain/test_core
CORE_ASAN_BIN   := $(BUILD)/asan/test_core
SIM_LIB         := $(BUILD)/sim/libroverlink_sim.so

.PHONY: core-test core-test-plain core-test-asan sim core-avr

core-test: core-test-plain core-test-asan

core-test-plain: $(CORE_PLAIN_BIN)
	@echo "== firmware core tests (plain) =="
	$(CORE_PLAIN_BIN)

core-test-asan: $(CORE_ASAN_BIN)
	@echo "== firmware core tests (address,undefined sanitizers) =="
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 $(CORE_ASAN_BIN)

$(CORE_PLAIN_BIN): $(CORE_DEPS) $(CORE_DIR)/test_core.cpp $(CORE_DIR)/sim_api.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_COMMON) $(CORE_INCLUDES) $(CORE_TEST_SRCS) -o $@

$(CORE_ASAN_BIN): $(CORE_DEPS) $(CORE_DIR)/test_core.cpp $(CORE_DIR)/sim_api.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_COMMON) $(SANFLAGS) $(CORE_INCLUDES) $(CORE_TEST_SRCS) -o $@

# UBSan only (ASan needs to be preloaded into a Python process; UBSan links in as a shared runtime),
# aborting on the first report so a Python test dies loudly instead of passing.
sim: $(SIM_LIB)

$(SIM_LIB): $(CORE_DEPS) $(CORE_DIR)/sim_api.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_COMMON) -fPIC -shared -fsanitize=undefined -fno-sanitize-recover=all $(CORE_INCLUDES) \
	    $(CORE_DIR)/sim_api.cpp $(CORE_LIB_SRCS) -o $@.tmp && mv $@.tmp $@

# The core as the Arduino IDE compiles it: every .cpp under src/core and src/hal/native (the latter
# must compile to nothing), -DARDUINO against the Arduino AVR core headers.
ARDUINO_AVR   ?= /usr/share/arduino/hardware/arduino/avr
CORE_AVR_MCU  ?= atmega328p
CORE_AVR_VAR  ?= standard
CORE_AVR_FLAGS := -std=gnu++11 -mmcu=$(CORE_AVR_MCU) -Os -Wall -Wextra -Werror -ffunction-sections -fdata-sections \
                  -I$(SRC) -I$(ARDUINO_AVR)/cores/arduino -I$(ARDUINO_AVR)/variants/$(CORE_AVR_VAR) \
                  -DARDUINO=10800 -DF_CPU=16000000L
CORE_AVR_OBJS := $(addprefix $(BUILD)/core-avr/$(CORE_AVR_MCU)/,$(notdir $(CORE_SRCS:.cpp=.o) $(NATIVE_HAL:.cpp=.o)))
CORE_AVR_PROBE := $(BUILD)/core-avr/$(CORE_AVR_MCU)/size_probe.o

core-avr:
ifeq ($(shell command -v $(AVR_CXX) 2>/dev/null),)
	@echo "core-avr: SKIPPED, $(AVR_CXX) not found (install gcc-avr and avr-libc)"
else ifeq ($(wildcard $(ARDUINO_AVR)/cores/arduino/Arduino.h),)
	@echo "core-avr: SKIPPED, no Arduino AVR core at $(ARDUINO_AVR) (install arduino-core-avr)"
else
	@$(MAKE) --no-print-directory -f $(HERE)/Makefile BUILD=$(BUILD) core-avr-objs
endif

.PHONY: core-avr-objs
core-avr-objs: $(CORE_AVR_OBJS) $(CORE_AVR_PROBE)
	$(AVR_SIZE) $(CORE_AVR_OBJS)
	@avr-nm -S -C $(CORE_AVR_PROBE) | grep ' sizeof_' | while read addr size kind name; do \
	    printf '%s on $(CORE_AVR_MCU): %d bytes\n' "$$name" "0x$$size"; done

$(BUILD)/core-avr/$(CORE_AVR_MCU)/%.o: $(SRC)/core/%.cpp $(CORE_HDRS) $(RUNTIME_HDRS) $(PROTO_HDRS) $(CORE_DIR)/core.mk
	@mkdir -p $(dir $@)
	$(AVR_CXX) $(CORE_AVR_FLAGS) -c $< -o $@

$(BUILD)/core-avr/$(CORE_AVR_MCU)/%.o: $(SRC)/hal/native/%.cpp $(CORE_HDRS) $(CORE_DIR)/core.mk
	@mkdir -p $(dir $@)
	$(AVR_CXX) $(CORE_AVR_FLAGS) -c $< -o $@

$(CORE_AVR_PROBE): $(CORE_DIR)/avr_size_probe.cpp $(CORE_HDRS) $(RUNTIME_HDRS) $(PROTO_HDRS) $(CORE_DIR)/core.mk
	@mkdir -p $(dir $@)
	$(AVR_CXX) $(CORE_AVR_FLAGS) -c $< -o $@
