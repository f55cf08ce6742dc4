#pragma once
// Tables of malformed scene texts and the error each must give.
#include <gtest/gtest.h>

#include <span>
#include <string>

#include "scene/load.h"
#include "scene/nff_text.h"

namespace raypack {

struct BadScene {
    const char* text;
    int line;             ///< the line the error names
    const char* message;  ///< a part of the message
};

/// Each text must fail to load (as NFF named test.nff) with a SceneError
/// naming its line and containing its message.
inline void expect_scene_errors(std::span<const BadScene> cases) {
    for (const BadScene& b : cases) {
        try {
            load_nff_text(b.text, "test.nff");
            ADD_FAILURE() << "accepted: " << b.text;
        } catch (const SceneError& e) {
            EXPECT_EQ(e.line(), b.line) << b.text << " -> " << e.what();
            EXPECT_NE(std::string(e.what()).find(b.message), std::string::npos) << b.text << " -> " << e.what();
        }
    }
}

}  // namespace raypack
