#include "actions.h"
#include "main_window.h"

#include <QAction>
#include <QActionGroup>
#include <QDir>
#include <QMainWindow>
#include <QMenu>
#include <QMenuBar>
#include <QToolBar>

namespace tyndall::studio {

ActionTable::ActionTable(QMainWindow* window) : QObject(window), window_(window) {}

QMenu* ActionTable::menu(const QString& path) {
    if (auto it = menus_.find(path); it != menus_.end()) return it->second;
    const qsizetype slash = path.lastIndexOf('/');
    QMenu* menu =
        slash < 0 ? window_->menuBar()->addMenu(path) : this->menu(path.left(slash))->addMenu(path.mid(slash + 1));
    menus_[path] = menu;
    return menu;
}

QToolBar* ActionTable::toolbar(const QString& id, const QString& title) {
    QToolBar*& bar = toolbars_[id];
    if (!bar) {
        bar = window_->addToolBar(title);
        bar->setObjectName(id);
    }
    return bar;
}

void ActionTable::separator(const QString& menuPath) {
    menu(menuPath)->addSeparator();
}

QAction* ActionTable::add(const ActionSpec& spec) {
    auto* action = new QAction(spec.text, window_);
    connect(action, &QAction::triggered, this, [run = spec.run] { run(); });
    return add(action, spec);
}

QAction* ActionTable::add(QAction* action, const ActionSpec& spec) {
    if (!spec.id.isEmpty()) action->setObjectName(spec.id);
    if (!spec.keys.isEmpty()) {
        action->setShortcuts(spec.keys);
        action->setShortcutContext(spec.context);
    }
    if (!spec.tip.isEmpty()) action->setToolTip(spec.tip);
    action->setCheckable(spec.checkable || !spec.group.isEmpty());
    if (!spec.group.isEmpty()) {
        QActionGroup*& group = groups_[spec.group];
        if (!group) {
            group = new QActionGroup(this);
            action->setChecked(true);  // the first of a group
        }
        group->addAction(action);
    }
    menu(spec.menu)->addAction(action);
    if (!spec.toolbar.isEmpty()) toolbar(spec.toolbar, spec.toolbar)->addAction(action);
    actions_.emplace_back(action, spec.menu);
    return action;
}

QAction* ActionTable::action(const QString& id) const {
    for (const auto& [a, menu] : actions_)
        if (a->objectName() == id) return a;
    return nullptr;
}

bool ActionTable::trigger(int key, Qt::KeyboardModifiers modifiers) const {
    // A shifted digit arrives as its symbol on a US layout; its action's key is Shift+digit.
    static const int shifted[] = {Qt::Key_Exclam,    Qt::Key_At,       Qt::Key_NumberSign,
                                  Qt::Key_Dollar,    Qt::Key_Percent,  Qt::Key_AsciiCircum,
                                  Qt::Key_Ampersand, Qt::Key_Asterisk, Qt::Key_ParenLeft};
    for (int i = 0; i < 9; ++i)
        if (key == shifted[i]) key = Qt::Key_1 + i, modifiers |= Qt::ShiftModifier;
    const QKeySequence pressed(QKeyCombination(modifiers & ~Qt::KeypadModifier, Qt::Key(key)));
    for (const auto& [action, menu] : actions_) {
        if (!action->isEnabled() || !action->shortcuts().contains(pressed)) continue;
        action->trigger();
        return true;
    }
    return false;
}

QString ActionTable::helpHtml(const std::vector<Binding>& mouse) const {
    QString html = "<table cellspacing=4>";
    auto row = [&html](const QString& keys, const QString& text, const QString& where) {
        html += "<tr><td><b>" + keys.toHtmlEscaped() + "</b></td><td>" + text.toHtmlEscaped() + "</td><td><i>" +
                where.toHtmlEscaped() + "</i></td></tr>";
    };
    for (const auto& [action, menu] : actions_) {
        if (action->shortcuts().isEmpty()) continue;
        QStringList keys;
        for (const QKeySequence& k : action->shortcuts())
            keys << k.toString(QKeySequence::NativeText);
        row(keys.join(", "), QString(action->text()).remove('&'), QString(menu).remove('&').replace("/", " > "));
    }
    for (const auto& [what, does] : mouse)
        row(what, does, "viewport");
    return html + "</table>";
}

void addStudioActions(ActionTable& table, MainWindow& window) {
    Studio& studio = window.studio();
    const QString file = "&File", edit = "&Edit", view = "&View", views = "&View/&Views";
    table.add({"open", file, "&Open...", {QKeySequence(QKeySequence::Open)}, [&window] { window.openDialog(); }});
    table.add({"save", file, "&Save", {QKeySequence(QKeySequence::Save)}, [&window] { window.save(); }});
    table.add(
        {"saveAs", file, "Save &as...", {QKeySequence(QKeySequence::SaveAs)}, [&window] { window.saveAsDialog(); }});
    table.menu(file + "/Open &recent")->setObjectName("recentMenu");
    table.add({"openImage",
               file,
               "Open &image...",
               {QKeySequence("Ctrl+I")},
               [&window] { window.openImageDialog(); },
               {},
               "Open EXR, HDR or PNG images (also by drag and drop) as views that take part in every comparison"});
    table.separator(file);
    table.add({"export", file, "&Export comparison...", {}, [&window] { window.exportDialog(); }});
    table.add({"clearCache", file, "Clear the reference cache", {}, [] {
                   QDir(Studio::referenceCacheFolder()).removeRecursively();
               }});
    table.separator(file);
    table.add({"quit",
               file,
               "&Quit",
               {QKeySequence(QKeySequence::Quit)},
               [&window] { window.close(); },
               {},
               {},
               false,
               {},
               Qt::WindowShortcut});

    QList<QKeySequence> redoKeys = QKeySequence::keyBindings(QKeySequence::Redo);
    for (const QKeySequence& key : {QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")})
        if (!redoKeys.contains(key)) redoKeys << key;  // both, on every platform
    QUndoStack* undo = studio.session().undoStack();
    table.add(undo->createUndoAction(&window, "&Undo"), {"undo", edit, {}, {QKeySequence(QKeySequence::Undo)}});
    table.add(undo->createRedoAction(&window, "&Redo"), {"redo", edit, {}, redoKeys});

    // The display of every view (compositor.h).
    table.add({"layout:grid",
               view,
               "&Grid",
               {QKeySequence("G")},
               [&studio] { studio.setLayoutMode(Layout::Grid); },
               "layoutToolbar",
               {},
               true,
               "layout"});
    table.add({"layout:single",
               view,
               "&Single",
               {QKeySequence("S")},
               [&studio] { studio.setLayoutMode(Layout::Single); },
               "layoutToolbar",
               {},
               true,
               "layout"});
    table.add({"layout:split",
               view,
               "Split (&wipe)",
               {QKeySequence("W")},
               [&studio] { studio.setLayoutMode(Layout::Split); },
               "layoutToolbar",
               {},
               true,
               "layout"});
    table.separator(view);
    table.add({"difference",
               view,
               "Cycle &difference (off, signed, absolute, relative, FLIP)",
               {QKeySequence("D")},
               [&studio] { studio.cycleDifference(); },
               "layoutToolbar"});
    table.add({"display",
               view,
               "Cycle the display &transform (OpenColorIO's views, then Tyndall's sRGB, Reinhard, ACES fit, false "
               "colour)",
               {QKeySequence("M")},
               [&studio] { studio.cycleDisplayTransform(); }});
    table.add({"swap",
               view,
               "Swap the wipe's sides",
               {QKeySequence("T")},
               [&studio] { studio.swapSides(); },
               "layoutToolbar"});
    table.separator(view);
    table.add({"exposure+", view, "Display exposure offset +0.5 EV (all views)", {QKeySequence("E")}, [&studio] {
                   studio.offsetExposure(0.5);
               }});
    table.add({"exposure-", view, "Display exposure offset -0.5 EV (all views)", {QKeySequence("Shift+E")}, [&studio] {
                   studio.offsetExposure(-0.5);
               }});
    table.add({"resetZoom", view, "Reset zoom and pan", {QKeySequence("Z")}, [&studio] { studio.resetZoom(); }});
    table.add(
        {"smoothPreviews",
         view,
         "Smooth reduced images (bilinear; else nearest)",
         {},
         [&studio] { studio.setSmoothPreviews(!studio.compositorState().smoothPreviews); },
         {},
         "After an edit a slow view shows a reduced image first (1/2 to 1/16 of its resolution), scaled up to its "
         "tile: with its pixels visible (nearest), or smoothed (bilinear)",
         true});
    table.add({"clearRegion",
               view,
               "Clear the metrics region",
               {QKeySequence("Esc")},
               [&studio] { studio.setRegion(QRect()); },
               {},
               {},
               false,
               {},
               Qt::WindowShortcut});
    for (int i = 0; i < 9; ++i)
        table.add({QString("view:%1").arg(i + 1),
                   views,
                   QString("Show view %1 alone").arg(i + 1),
                   {QKeySequence(QString::number(i + 1))},
                   [&studio, i] { studio.showViewAlone(i); }});
    table.separator(views);
    for (int i = 0; i < 9; ++i)
        table.add({QString("compareWith:%1").arg(i + 1),
                   views,
                   QString("Compare every view against view %1 (again: the reference)").arg(i + 1),
                   {QKeySequence(QString("Shift+%1").arg(i + 1))},
                   [&studio, i] { studio.toggleReferenceView(i); }});

    table.add({"frameScene", "&Camera", "&Frame the scene", {QKeySequence("F")}, [&studio] { studio.frameScene(); }});
    table.add({"takeSnapshot", "S&napshots", "&Take a snapshot of the current view", {QKeySequence("K")}, [&studio] {
                   studio.takeSnapshot();
               }});

    // The particle simulation: enabled, and its toolbar shown, only for a project with a particle medium.
    const QString animation = "&Animation";
    table.add({"playAnimation",
               animation,
               "&Play",
               {QKeySequence("P")},
               [&studio] { studio.animation().togglePlay(); },
               "animationToolbar",
               "Play or pause the particle simulation (P): each time the views have shown the last frame it advances "
               "by the time that passed, up to the pace's steps a frame (the box beside it)",
               true});
    table.add({"stepAnimation",
               animation,
               "&Step",
               {QKeySequence(".")},
               [&studio] { studio.stepAnimation(); },
               "animationToolbar"});
    table.add({"resetAnimation",
               animation,
               "&Reset (step 0, no impulses, targets back)",
               {QKeySequence("Ctrl+R")},
               [&studio] { studio.resetAnimation(); },
               "animationToolbar"});

    const QString help = "&Help";
    table.add(
        {"shortcuts", help, "&Keyboard and mouse shortcuts", {QKeySequence(Qt::Key_F1), QKeySequence("?")}, [&window] {
             window.showShortcuts();
         }});
    table.add({"documentation", help, "&Documentation", {}, [&window] { window.showDocumentation(); }});
    table.add({"about", help, "&About Tyndall Studio", {}, [&window] { window.showAbout(); }});
}

}  // namespace tyndall::studio
