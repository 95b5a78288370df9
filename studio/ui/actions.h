// One table of the studio's actions: id, menu, text, keys and what it does (and a toolbar, a tip, a check). It feeds
// the menus, the toolbars, the viewport's keys (a key pressed over the Vulkan viewport, which is a QWindow outside the
// widget tree where shortcuts fire, triggers the action whose shortcut it is) and the help overlay, so that a key is
// defined once and every list of keys is true.
#pragma once

#include <QKeySequence>
#include <QList>
#include <QObject>
#include <QString>

#include <functional>
#include <map>
#include <utility>
#include <vector>

class QAction;
class QActionGroup;
class QMainWindow;
class QMenu;
class QToolBar;

namespace tyndall::studio {

class MainWindow;

struct ActionSpec {
    QString id;    // the QAction's objectName (empty: none)
    QString menu;  // "&View" or "&View/&Views" (a submenu)
    QString text;
    QList<QKeySequence> keys;
    std::function<void()> run;
    QString toolbar;  // the objectName of a toolbar it is also on (empty: none)
    QString tip;
    bool checkable = false;
    QString group;  // checkable actions of one exclusive group (one of them checked)
    // Keys work wherever the focus is (a dock's list never swallows them); Esc only in the window (not in dialogs).
    Qt::ShortcutContext context = Qt::ApplicationShortcut;
};

// Mouse bindings and held keys for the help overlay: what, and what it does.
using Binding = std::pair<QString, QString>;

class ActionTable : public QObject {
    Q_OBJECT
public:
    explicit ActionTable(QMainWindow* window);
    QAction* add(const ActionSpec& spec);
    // An action made elsewhere (undo and redo come from the undo stack), placed and listed like the others.
    QAction* add(QAction* action, const ActionSpec& spec);
    QMenu* menu(const QString& path);  // made on first use, menus in the order of first use
    QToolBar* toolbar(const QString& id, const QString& title);
    void separator(const QString& menuPath);
    QAction* action(const QString& id) const;
    // The enabled action whose shortcut is `key` with `modifiers` (a shifted digit's symbol counts as Shift+digit):
    // triggered, true; false when there is none.
    bool trigger(int key, Qt::KeyboardModifiers modifiers) const;
    // Every action with a key, in the table's order, then `mouse`, as an HTML table: keys, text, where.
    QString helpHtml(const std::vector<Binding>& mouse) const;

private:
    QMainWindow* window_;
    std::map<QString, QMenu*> menus_;
    std::map<QString, QToolBar*> toolbars_;
    std::map<QString, QActionGroup*> groups_;
    std::vector<std::pair<QAction*, QString>> actions_;  // with their menu paths
};

// The studio's actions, in menu order.
void addStudioActions(ActionTable& table, MainWindow& window);

}  // namespace tyndall::studio
