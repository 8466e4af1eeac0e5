// The package version (package.xml's <version>) and the `--version` option every executable of
// birkhoff_cart understands: the apps in src/apps and the nodes in src/ros/nodes call
// print_version_if_asked() first thing in main (before ros::init for a node).
#pragma once

namespace birkhoff_cart {

/// The version of the package this binary was built from, e.g. "0.1.0".
const char* package_version();

/// When argv holds "--version": prints "<program> (birkhoff_cart) <version>" on stdout and returns
/// true (the caller then exits 0); otherwise false.
bool print_version_if_asked(int argc, char** argv, const char* program);

}  // namespace birkhoff_cart
