// The method table (sss_params.h, MethodInfo): one row per SSS method, each declared by its own file under
// renderer/sss/methods/ (method.h) and registered by one line, here for the built-in methods (docs/methods.md,
// "Adding a method").
#include "common/check.h"
#include "common/error.h"
#include "renderer/sss/method.h"

#include <algorithm>

namespace skinlab::renderer::sss {

// The built-in methods' registration lines, in table order: each names the function of its file under
// renderer/sss/methods/ that declares its row (name, executor, interactive, summary, keys, defaults, class).
// "none" comes first: SssMethod{} is its identifier.
#define SKINLAB_BUILT_IN_METHODS(METHOD)                                                                               \
    METHOD(noneMethod)                                                                                                 \
    METHOD(gaussianSumMethod)                                                                                          \
    METHOD(separableMethod)                                                                                            \
    METHOD(artisticMethod)                                                                                             \
    METHOD(pscbfMethod)                                                                                                \
    METHOD(referenceMethod)                                                                                            \
    METHOD(pathtracedMethod)                                                                                           \
    METHOD(eeveeMethod)

#define SKINLAB_DECLARE_METHOD(declaration) MethodInfo declaration();
SKINLAB_BUILT_IN_METHODS(SKINLAB_DECLARE_METHOD)
#undef SKINLAB_DECLARE_METHOD

// Defined in sss_params.cpp: adds a registered method's name to the sss.method choices.
void addMethodChoice(std::string_view name);

namespace {
// The checks of a row about to be added to `table`, and its identifier (its position).
void addRow(std::vector<MethodInfo>& table, MethodInfo row) {
    const std::string name(row.name);
    for (const MethodInfo& taken : table)
        if (taken.name == row.name) throw RuntimeError("method table: '" + name + "' is taken");
    if (!row.model) throw RuntimeError("method table: '" + name + "' has no class");
    // Every key of the table so far: the common ones, the shared ones its rows read and their own.
    std::vector<std::string_view> taken(kCommonSssKeys.begin(), kCommonSssKeys.end());
    for (const MethodInfo& other : table) {
        taken.insert(taken.end(), other.keys.begin(), other.keys.end());
        for (const SssKey& own : other.ownKeys) taken.push_back(own.name);
    }
    for (const SssKey& key : row.ownKeys)
        if (std::find(taken.begin(), taken.end(), key.name) != taken.end())
            throw RuntimeError("method table: '" + name + "' declares key '" + std::string(key.name) +
                               "', which another row declares");
    row.method = static_cast<SssMethod>(table.size());
    table.push_back(std::move(row));
}

// The table, the built-in methods first (built on first use, so a method registered from another file's static
// initialisation comes after them whichever file is initialised first).
std::vector<MethodInfo>& rows() {
    static std::vector<MethodInfo> table = [] {
        std::vector<MethodInfo> builtIn;
#define SKINLAB_ADD_METHOD(declaration) addRow(builtIn, declaration());
        SKINLAB_BUILT_IN_METHODS(SKINLAB_ADD_METHOD)
#undef SKINLAB_ADD_METHOD
        return builtIn;
    }();
    return table;
}
} // namespace

const std::vector<MethodInfo>& methodTable() { return rows(); }

const MethodInfo& methodInfo(SssMethod method) {
    const auto index = static_cast<std::size_t>(method);
    SKINLAB_CHECK(index < rows().size());
    return rows()[index];
}

const MethodInfo* findMethod(std::string_view name) {
    for (const MethodInfo& info : rows())
        if (info.name == name) return &info;
    return nullptr;
}

SssMethod registerMethod(MethodInfo row) {
    addRow(rows(), std::move(row));
    addMethodChoice(rows().back().name);
    return rows().back().method;
}

SssMethod methodId(std::string_view name) {
    const MethodInfo* info = findMethod(name);
    SKINLAB_CHECK(info != nullptr);
    return info->method;
}

std::vector<std::string> methodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> screenSpaceMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows())
        if (info.screenSpace()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> blurPassMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows())
        if (info.blurPasses()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string_view> allSssKeys() {
    std::vector<std::string_view> keys(kCommonSssKeys.begin(), kCommonSssKeys.end());
    const auto add = [&](std::string_view key) {
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    };
    for (const MethodInfo& info : rows()) {
        for (const std::string_view key : info.keys) add(key);
        for (const SssKey& key : info.ownKeys) add(key.name);
    }
    return keys;
}

bool methodUsesKey(SssMethod method, std::string_view key) {
    const MethodInfo& info = methodInfo(method);
    return std::find(kCommonSssKeys.begin(), kCommonSssKeys.end(), key) != kCommonSssKeys.end() ||
           std::find(info.keys.begin(), info.keys.end(), key) != info.keys.end() ||
           std::any_of(info.ownKeys.begin(), info.ownKeys.end(), [&](const SssKey& own) { return own.name == key; });
}

std::vector<std::string_view> methodKeys(SssMethod method) {
    std::vector<std::string_view> keys;
    for (const std::string_view k : kCommonSssKeys)
        if (k != "method") keys.push_back(k);
    // Its kernel's shared keys, its own keys, then the blur keys (kBlurKeys) it reads.
    const MethodInfo& info = methodInfo(method);
    const auto isBlurKey = [](std::string_view k) {
        return std::find(kBlurKeys.begin(), kBlurKeys.end(), k) != kBlurKeys.end();
    };
    for (const std::string_view k : info.keys)
        if (!isBlurKey(k)) keys.push_back(k);
    for (const SssKey& k : info.ownKeys) keys.push_back(k.name);
    for (const std::string_view k : info.keys)
        if (isBlurKey(k)) keys.push_back(k);
    return keys;
}

std::string notAParameterMessage(SssMethod method) {
    std::string keys;
    for (const std::string_view k : methodKeys(method)) keys += (keys.empty() ? "" : ", ") + std::string(k);
    return "not a parameter of method '" + std::string(methodName(method)) + "' (its keys: " + keys + ")";
}

std::string_view methodName(SssMethod method) { return methodInfo(method).name; }

std::string_view executionName(Execution execution) {
    switch (execution) {
    case Execution::CopyThrough: return "copy-through";
    case Execution::TapPasses: return "tap-passes";
    case Execution::Pscbf: return "pscbf";
    case Execution::ObjectSpace: return "object-space";
    case Execution::Cycles: return "cycles";
    case Execution::Eevee: return "eevee";
    }
    return "copy-through";
}

void to_json(nlohmann::json& out, SssMethod method) { out = std::string(methodName(method)); }

void from_json(const nlohmann::json& in, SssMethod& method) {
    const MethodInfo* info = in.is_string() ? findMethod(in.get<std::string>()) : nullptr;
    if (!info) throwInput("", "sss.method", in.dump() + " is not one of the methods (skinlab methods)");
    method = info->method;
}

} // namespace skinlab::renderer::sss
