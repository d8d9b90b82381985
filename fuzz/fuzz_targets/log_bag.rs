#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| onebeacon_fuzz::log_bag(data));
