// Links every optional component of the installed package (load, trace, device,
// harness, reference) and includes a header of each: their targets, include
// folders and dependencies resolve from an installed tree.
#include "gauss6/hid_device.h"
#include "gauss6/reference/ccd.h"
#include "gauss6/scenario.h"
#include "gauss6/io/scene.h"
#include "gauss6/trace.h"

int main() { return 0; }
