// spv_opt.cpp — spv_optimize (spv.h): spirv-opt's performance passes.
//
// C++ only because SPIRV-Tools 2023.1 exposes no C function that runs the
// optimiser (libspirv.h has spvOptimizerOptions* but nothing that takes
// them).  Keep this file to this one function.
#include "spv.h"

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <spirv-tools/optimizer.hpp>

extern "C" bool spv_optimize(uint32_t **words, size_t *nwords, char **log)
{
    if (log)
        *log = nullptr;
    std::string msgs;
    auto consumer = [&msgs](spv_message_level_t, const char *,
                            const spv_position_t &pos, const char *m) {
        msgs += "spirv-opt: ";
        msgs += m;
        msgs += " (word " + std::to_string(pos.index) + ")\n";
    };
    spvtools::Optimizer opt(SPV_ENV_VULKAN_1_2);
    opt.SetMessageConsumer(consumer);
    opt.RegisterPerformancePasses();

    spvtools::ValidatorOptions vopts;
    spvtools::OptimizerOptions oopts;
    oopts.set_run_validator(true);
    oopts.set_validator_options(vopts);
    oopts.set_preserve_bindings(true);   // the runtime binds by abi.h slots

    std::vector<uint32_t> out;
    bool ok = *words && opt.Run(*words, *nwords, &out, oopts) && !out.empty();
    if (ok) {
        // Re-validate: the runtime must never receive an invalid module.
        spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
        tools.SetMessageConsumer(consumer);
        ok = tools.Validate(out.data(), out.size(), vopts);
    }
    if (ok) {
        auto *w = static_cast<uint32_t *>(std::malloc(out.size() * sizeof(uint32_t)));
        if (!w) {
            msgs += "spirv-opt: out of memory\n";
            ok = false;
        } else {
            std::memcpy(w, out.data(), out.size() * sizeof(uint32_t));
            std::free(*words);
            *words = w;
            *nwords = out.size();
        }
    } else if (msgs.empty()) {
        msgs = "spirv-opt: optimisation failed\n";
    }
    if (log && !msgs.empty())
        *log = strdup(msgs.c_str());
    return ok;
}
