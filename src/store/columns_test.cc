#include "store/columns.h"
