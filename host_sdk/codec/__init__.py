"""The sans-I/O codec: COBS framing, CRC-16 with CRC_EXTRA, message base class."""
