// The studio's GUI tests: `tyndall_studio_tests [suite ...] [QTest options]` runs the named suites (all flow suites
// when none is named) in one process; the flow suites share one window.
#include "gui_test.h"

#include <QApplication>

#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>

namespace tyndall::studio::gui {
QObject* makeViewingTest(QVulkanInstance*);
QObject* makeRenderingTest(QVulkanInstance*);
QObject* makeEditingTest(QVulkanInstance*);
QObject* makeComparingTest(QVulkanInstance*);
QObject* makeProjectsTest(QVulkanInstance*);
QObject* makeExportTest(QVulkanInstance*);
QObject* makeLtsdPlotsTest(QVulkanInstance*);
QObject* makeAnimationTest(QVulkanInstance*);
}  // namespace tyndall::studio::gui

int main(int argc, char** argv) {
    using namespace tyndall::studio;
    using Make = QObject* (*)(QVulkanInstance*);
    // In this order when none is named; the LTSD plots and the animation only when named (their own ctest cases).
    const std::vector<std::pair<const char*, Make>> flows = {
        {"viewing", gui::makeViewingTest},     {"rendering", gui::makeRenderingTest}, {"editing", gui::makeEditingTest},
        {"comparing", gui::makeComparingTest}, {"projects", gui::makeProjectsTest},   {"export", gui::makeExportTest},
    };
    const std::map<std::string, Make> own = {{"ltsd-plots", gui::makeLtsdPlotsTest},
                                             {"animation", gui::makeAnimationTest}};
    std::vector<std::pair<std::string, Make>> chosen;
    std::vector<char*> args = {argv[0]};
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto flow = std::find_if(flows.begin(), flows.end(), [&](const auto& f) { return a == f.first; });
        if (flow != flows.end())
            chosen.emplace_back(a, flow->second);
        else if (own.count(a))
            chosen.emplace_back(a, own.at(a));
        else
            args.push_back(argv[i]);
    }
    if (chosen.empty())
        for (const auto& [name, make] : flows)
            chosen.emplace_back(name, make);

    // The display transforms of the shipped OpenColorIO config, whatever the user's $OCIO (a flow sets its own).
    qunsetenv("OCIO");
    QApplication app(argc, argv);
    QStandardPaths::setTestModeEnabled(true);  // settings and autosaves in a test location, not the user's
    QApplication::setOrganizationName("Tyndall");
    QApplication::setApplicationName("Tyndall Studio tests");
    QDir(Studio::referenceCacheFolder()).removeRecursively();  // every run renders its references once
    QVulkanInstance vulkan;
    vulkan.setApiVersion(QVersionNumber(1, 2));
    if (!vulkan.create()) {
        std::fprintf(stderr, "no Vulkan instance: %d\n", vulkan.errorCode());
        return 1;
    }
    int failed = 0;
    for (const auto& [name, make] : chosen) {
        std::unique_ptr<QObject> suite(make(&vulkan));
        failed += QTest::qExec(suite.get(), int(args.size()), args.data()) != 0;
    }
    gui::FlowCase::sharedWindow().reset();
    return failed;
}
