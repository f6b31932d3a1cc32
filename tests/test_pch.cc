// The translation unit that builds the test drivers' precompiled header (tests/test_pch.h); it
// has no code of its own.
