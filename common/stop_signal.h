#pragma once
/// @file
/// SIGINT / SIGTERM as a flag, for the loop of a process or tool that stops cleanly on Ctrl-C or
/// when supervisord stops it.

namespace bookgrasp {

/// Installs the handler of SIGINT and SIGTERM (once per process; calling again is harmless).
void install_stop_signals();

/// True once SIGINT or SIGTERM arrived after install_stop_signals().
bool stop_requested();

}  // namespace bookgrasp
